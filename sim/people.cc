#include "sim/people.h"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sim/floor_plan.h"
#include "sim/random.h"
#include "sim/textures.h"

namespace sim {
namespace {

constexpr int kLegTextures = 4;      // trousers shared by the people, person i wears i % 4
constexpr int kTorsoTexturePx = 64;  // a cube face's side (texels)
constexpr double kLineStepM = 0.05;  // MJCF scenes: the lines' samples and offsets (m)
constexpr double kMinOffsetM = 0.5;  // the offsets tried beside the robot's path (m)
constexpr double kMaxOffsetM = 3.0;
constexpr uint64_t kPeopleStream = 5;  // DeriveSeed(seed, i, kPeopleStream)

std::string Num(double v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

double WallDistance(const SceneWall& w, const Eigen::Vector2d& p) {
  if (!std::isfinite(w.half_length_m)) {
    const Eigen::Vector2d n(-w.along_xy.y(), w.along_xy.x());
    return std::abs(n.dot(p - w.centre_xy));
  }
  return PointSegmentDistance(p, w.centre_xy - w.half_length_m * w.along_xy,
                              w.centre_xy + w.half_length_m * w.along_xy);
}

bool OverFloor(const std::vector<SceneFloor>& floors, const Eigen::Vector2d& p) {
  if (floors.empty()) return true;
  for (const SceneFloor& f : floors) {
    const Eigen::Vector2d d = p - f.centre_xy;
    if (std::abs(d.dot(f.axis_xy[0])) <= f.half_size_m[0] &&
        std::abs(d.dot(f.axis_xy[1])) <= f.half_size_m[1])
      return true;
  }
  return false;
}

double PolylineLength(const std::vector<Eigen::Vector2d>& p) {
  double l = 0.0;
  for (size_t i = 1; i < p.size(); ++i) l += (p[i] - p[i - 1]).norm();
  return l;
}

// A stretch of clear samples beside a robot segment: the line from `a` along `dir`, samples
// first..last (inclusive).
struct Line {
  Eigen::Vector2d a, dir;
  int first = 0, last = 0;
};

bool LinesBesideThePath(const Scenario& s, const std::vector<SceneWall>& walls,
                        const std::vector<SceneFloor>& floors, std::vector<Line>* lines) {
  const double h = s.people.height_m;
  const double wall_clear = kPersonClearance * h;
  const double robot_clear = kRobotClearanceM + kPersonClearance * h;
  std::vector<const SceneWall*> tall;  // the walls a person meets: spanning some of its height
  for (const SceneWall& w : walls)
    if (w.z_min_m < h && w.z_max_m > 0.0) tall.push_back(&w);
  const auto clear = [&](const Eigen::Vector2d& p) {
    for (const SceneWall* w : tall)
      if (WallDistance(*w, p) < wall_clear) return false;
    for (size_t j = 1; j < s.path.size(); ++j)
      if (PointSegmentDistance(p, s.path[j - 1], s.path[j]) < robot_clear) return false;
    return OverFloor(floors, p);
  };
  const int min_samples = static_cast<int>(std::ceil(kMinPersonLineM / kLineStepM));
  for (size_t j = 1; j < s.path.size(); ++j) {
    const Eigen::Vector2d seg = s.path[j] - s.path[j - 1];
    const double len = seg.norm();
    if (len < kMinPersonLineM) continue;
    const Eigen::Vector2d dir = seg / len, normal(-dir.y(), dir.x());
    const int samples = static_cast<int>(std::floor(len / kLineStepM));
    for (int side = -1; side <= 1; side += 2) {
      for (int k = 0; kMinOffsetM + k * kLineStepM <= kMaxOffsetM + 1e-9; ++k) {
        const double offset = kMinOffsetM + k * kLineStepM;
        const Eigen::Vector2d a = s.path[j - 1] + side * offset * normal;
        int run = -1;
        for (int q = 0; q <= samples + 1; ++q) {
          const bool ok = q <= samples && clear(a + q * kLineStepM * dir);
          if (ok && run < 0) run = q;
          if (!ok && run >= 0) {
            if (q - 1 - run >= min_samples) lines->push_back({a, dir, run, q - 1});
            run = -1;
          }
        }
      }
    }
  }
  return !lines->empty();
}

// The body's pose: the mocap body at (x, y, 0) turned by yaw about z.
void SetMocap(mjData* d, int mocap, const Eigen::Vector3d& pos, const Eigen::Quaterniond& q) {
  for (int c = 0; c < 3; ++c) d->mocap_pos[3 * mocap + c] = pos[c];
  d->mocap_quat[4 * mocap + 0] = q.w();
  d->mocap_quat[4 * mocap + 1] = q.x();
  d->mocap_quat[4 * mocap + 2] = q.y();
  d->mocap_quat[4 * mocap + 3] = q.z();
}

// Fills texture `t` (all of its texels: a cube's six faces one below the other) with a generated
// texture of `kind`.
bool FillTexture(mjModel* m, int t, TextureKind kind, TextureOptions options, uint64_t seed) {
  const int w = m->tex_width[t], h = m->tex_height[t];
  options.px_per_m = 256.0;
  cv::Mat img = GenerateTexture(kind, w / options.px_per_m, h / options.px_per_m, seed, options);
  if (img.empty() || img.type() != CV_8UC3) return false;
  if (img.cols != w || img.rows != h) cv::resize(img, img, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  cv::cvtColor(img, img, cv::COLOR_BGR2RGB);
  unsigned char* dst = m->tex_rgb + m->tex_adr[t];
  for (int r = 0; r < h; ++r)
    std::memcpy(dst + static_cast<size_t>(r) * w * 3, img.ptr(r), static_cast<size_t>(w) * 3);
  return true;
}

}  // namespace

bool PlanPeople(const Scenario& s, const std::vector<SceneWall>& walls,
                const std::vector<SceneFloor>& floors, std::vector<PersonPath>* paths,
                std::string* error) {
  paths->clear();
  const PeopleOptions& o = s.people;
  if (o.count == 0) return true;
  FloorPlan plan;
  bool on_plan = false;
  if (IsFloorPlanPath(s.scene_path)) {
    if (!LoadFloorPlan(s.scene_path, &plan, error)) return false;
    on_plan = plan.places.size() >= 2;
  }
  std::vector<Line> lines;
  if (!on_plan && !LinesBesideThePath(s, walls, floors, &lines)) {
    *error = "no line of " + Num(kMinPersonLineM) + " m beside the robot's path keeps " +
             Num(kPersonClearance * o.height_m) + " m from the walls and " +
             Num(kRobotClearanceM + kPersonClearance * o.height_m) +
             " m from the robot's path (people of height " + Num(o.height_m) +
             " m); a floor plan with named places lets them walk between those";
    return false;
  }
  for (int i = 0; i < o.count; ++i) {
    SplitMix64 rng(DeriveSeed(o.seed, static_cast<uint64_t>(i), kPeopleStream));
    PersonPath p;
    if (on_plan) {
      const size_t n = plan.places.size();
      std::string why;
      for (size_t attempt = 0; attempt < 4 * n * n && p.points.empty(); ++attempt) {
        const size_t a = static_cast<size_t>(rng.Uniform() * n);
        size_t b = static_cast<size_t>(rng.Uniform() * (n - 1));
        if (b >= a) ++b;
        std::vector<Eigen::Vector2d> planned;
        if (PlanPath(plan, plan.places[a].second, plan.places[b].second,
                     kPersonClearance * o.height_m, &planned, &why))
          p.points = planned;
      }
      if (p.points.empty()) {
        *error = "no path for person " + std::to_string(i) + " between the places of " +
                 s.scene_path + " keeping " + Num(kPersonClearance * o.height_m) +
                 " m from the walls (" + why + ")";
        return false;
      }
    } else {
      const Line& l = lines[static_cast<size_t>(rng.Uniform() * lines.size())];
      const int available = l.last - l.first;  // in steps
      const int max_steps = static_cast<int>(std::floor(kMaxPersonLineM / kLineStepM));
      const int min_steps = static_cast<int>(std::ceil(kMinPersonLineM / kLineStepM));
      const int top = std::min(available, max_steps);
      const int steps = min_steps + static_cast<int>(rng.Uniform() * (top - min_steps + 1));
      const int start = l.first + static_cast<int>(rng.Uniform() * (available - steps + 1));
      p.points = {l.a + start * kLineStepM * l.dir, l.a + (start + steps) * kLineStepM * l.dir};
    }
    p.length_m = PolylineLength(p.points);
    p.phase_m = rng.Uniform() * 2.0 * p.length_m;
    paths->push_back(p);
  }
  return true;
}

PersonPose PersonAt(const PersonPath& path, double speed_mps, double t_s) {
  PersonPose pose;
  const double round_trip = 2.0 * path.length_m;
  pose.walked_m = path.phase_m + speed_mps * t_s;
  double u = std::fmod(pose.walked_m, round_trip);
  if (u < 0) u += round_trip;
  const bool back = u > path.length_m;
  double along = back ? round_trip - u : u;
  for (size_t i = 1; i < path.points.size(); ++i) {
    const Eigen::Vector2d seg = path.points[i] - path.points[i - 1];
    const double len = seg.norm();
    if (along <= len || i + 1 == path.points.size()) {
      const Eigen::Vector2d dir = len > 0 ? Eigen::Vector2d(seg / len) : Eigen::Vector2d::UnitX();
      pose.xy = path.points[i - 1] + std::min(along, len) * dir;
      const Eigen::Vector2d heading = back ? Eigen::Vector2d(-dir) : dir;
      pose.yaw_rad = std::atan2(heading.y(), heading.x());
      return pose;
    }
    along -= len;
  }
  pose.xy = path.points.front();
  return pose;
}

std::string PeopleMjcf(const PeopleOptions& o) {
  const double h = o.height_m;
  std::ostringstream x;
  const std::string no_contact = "\" contype=\"0\" conaffinity=\"0\" group=\"0\"/>\n";
  x << "  <asset>\n";
  const auto cube = [&](const std::string& name, const std::string& rgba) {
    x << "    <texture name=\"" << name << "\" type=\"cube\" builtin=\"flat\" rgb1=\"0.5 0.5 0.5\" "
      << "width=\"" << kTorsoTexturePx << "\" height=\"" << kTorsoTexturePx << "\"/>\n"
      << "    <material name=\"" << name << "\" texture=\"" << name << "\" rgba=\"" << rgba
      << "\" emission=\"0.6\" specular=\"0\" shininess=\"0\" reflectance=\"0\"/>\n";
  };
  for (int i = 0; i < o.count; ++i) cube("person" + std::to_string(i) + "_torso", "1 1 1 1");
  for (int k = 0; k < std::min(o.count, kLegTextures); ++k)
    cube("person_legs" + std::to_string(k), "0.55 0.55 0.6 1");
  cube("person_head", "0.95 0.75 0.6 1");
  x << "  </asset>\n  <worldbody>\n";
  for (int i = 0; i < o.count; ++i) {
    const std::string p = "person" + std::to_string(i);
    x << "    <body name=\"" << p << "\" mocap=\"true\" pos=\"0 0 -10\">\n"
      << "      <geom name=\"" << p << "_torso\" type=\"box\" size=\"" << Num(0.07 * h) << " "
      << Num(0.11 * h) << " " << Num(0.175 * h) << "\" pos=\"0 0 " << Num(0.645 * h)
      << "\" material=\"" << p << "_torso" << no_contact;
    for (int side = -1; side <= 1; side += 2)
      x << "      <geom name=\"" << p << (side < 0 ? "_arm_r" : "_arm_l")
        << "\" type=\"capsule\" size=\"" << Num(0.028 * h) << "\" fromto=\"0 "
        << Num(side * 0.14 * h) << " " << Num(0.80 * h) << " 0 " << Num(side * 0.14 * h) << " "
        << Num(0.47 * h) << "\" material=\"" << p << "_torso" << no_contact;
    x << "      <geom name=\"" << p << "_neck\" type=\"capsule\" size=\"" << Num(0.025 * h)
      << "\" fromto=\"0 0 " << Num(0.80 * h) << " 0 0 " << Num(0.87 * h)
      << "\" material=\"person_head" << no_contact;
    x << "      <geom name=\"" << p << "_head\" type=\"sphere\" size=\"" << Num(0.07 * h)
      << "\" pos=\"0 0 " << Num(0.92 * h) << "\" material=\"person_head" << no_contact;
    x << "    </body>\n";
    for (const char* leg : {"_leg_l", "_leg_r"})
      x << "    <body name=\"" << p << leg << "\" mocap=\"true\" pos=\"0 0 -10\">\n"
        << "      <geom name=\"" << p << leg << "\" type=\"box\" size=\"" << Num(0.045 * h) << " "
        << Num(0.04 * h) << " " << Num(0.245 * h) << "\" pos=\"0 0 " << Num(-0.245 * h)
        << "\" material=\"person_legs" << (i % kLegTextures) << no_contact << "    </body>\n";
  }
  x << "  </worldbody>\n";
  return x.str();
}

bool People::Init(mjModel* m, const PeopleOptions& options, std::vector<PersonPath> paths,
                  std::string* error) {
  options_ = options;
  paths_ = std::move(paths);
  mocap_.clear();
  for (int i = 0; i < options.count; ++i) {
    const std::string p = "person" + std::to_string(i);
    for (const std::string& name : {p, p + "_leg_l", p + "_leg_r"}) {
      const int b = mj_name2id(m, mjOBJ_BODY, name.c_str());
      if (b < 0 || m->body_mocapid[b] < 0) {
        *error = "the scene lacks the mocap body '" + name + "' of the people";
        return false;
      }
      mocap_.push_back(m->body_mocapid[b]);
    }
  }
  // Clothes: each torso its own busy furniture-like texture (prints and patches), the trousers
  // tiles (a check), the head a plain skin; all from the people's seed.
  for (int t = 0; t < m->ntex; ++t) {
    const char* n = mj_id2name(m, mjOBJ_TEXTURE, t);
    const std::string name = n ? n : "";
    if (name.rfind("person", 0) != 0) continue;
    TextureOptions to;
    TextureKind kind = TextureKind::kWall;
    if (name == "person_head") {
      kind = TextureKind::kPlainWall;
      to.doors = false;
      to.skirting_height_m = 0.0;
    } else if (name.rfind("person_legs", 0) == 0) {
      kind = TextureKind::kFloor;
      to.floor_tile_m = 0.06;
      to.grout_width_m = 0.006;
    } else {
      to.doors = false;
      to.skirting_height_m = 0.0;
      to.detail_density = 3.0;
      to.poster_share = 0.9;
    }
    uint64_t h = 1469598103934665603ull;  // FNV-1a of the name
    for (unsigned char c : name) h = (h ^ c) * 1099511628211ull;
    if (!FillTexture(m, t, kind, to, DeriveSeed(options.seed, h, kPeopleStream))) {
      *error = "the texture generator failed for '" + name + "'";
      return false;
    }
  }
  return true;
}

void People::Apply(const mjModel* m, mjData* d, double t_s) const {
  (void)m;
  const double h = options_.height_m;
  for (size_t i = 0; i < paths_.size(); ++i) {
    const PersonPose pose = PersonAt(paths_[i], options_.speed_mps, t_s);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(pose.yaw_rad, Eigen::Vector3d::UnitZ()));
    SetMocap(d, mocap_[3 * i], Eigen::Vector3d(pose.xy.x(), pose.xy.y(), 0.0), q);
    const double swing =
        kLegSwingDeg * M_PI / 180.0 * std::sin(2.0 * M_PI * pose.walked_m / (kStridePerHeight * h));
    for (int leg = 0; leg < 2; ++leg) {
      const double side = leg == 0 ? 1.0 : -1.0;  // left: +y in the person's frame
      const Eigen::Vector3d hip = Eigen::Vector3d(pose.xy.x(), pose.xy.y(), 0.49 * h) +
                                  q * Eigen::Vector3d(0.0, side * 0.055 * h, 0.0);
      const Eigen::Quaterniond ql = q * Eigen::AngleAxisd(side * swing, Eigen::Vector3d::UnitY());
      SetMocap(d, mocap_[3 * i + 1 + leg], hip, ql);
    }
  }
}

}  // namespace sim
