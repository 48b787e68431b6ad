// Floor plans: reading and checking (file:line errors), the planes, the MJCF (see floor_plan.h).
#include "sim/floor_plan.h"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <queue>
#include <set>
#include <sstream>

#include "sim/data_dir.h"
#include "sim/yaml_input.h"

namespace sim {
namespace {

namespace fs = std::filesystem;

constexpr double kEps = 1e-9;  // geometric tolerance (m)

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}
Eigen::Vector2d LeftNormal(const Eigen::Vector2d& d) { return Eigen::Vector2d(-d.y(), d.x()); }

std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.12g", std::abs(v) < 5e-13 ? 0.0 : v);
  return buf;
}
std::string Pt(const Eigen::Vector2d& p) { return "(" + Num(p.x()) + ", " + Num(p.y()) + ")"; }

// Whether segments a0-a1 and b0-b1 share a point (touching included).
bool SegmentsTouch(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1, const Eigen::Vector2d& b0,
                   const Eigen::Vector2d& b1) {
  return PointSegmentDistance(a0, b0, b1) < kEps || PointSegmentDistance(a1, b0, b1) < kEps ||
         PointSegmentDistance(b0, a0, a1) < kEps || PointSegmentDistance(b1, a0, a1) < kEps ||
         (Cross(a1 - a0, b0 - a0) * Cross(a1 - a0, b1 - a0) < 0 &&
          Cross(b1 - b0, a0 - b0) * Cross(b1 - b0, a1 - b0) < 0);
}

// Whether segments cross at a point inside both (touching and collinear overlap are not).
bool SegmentsCrossProperly(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1,
                           const Eigen::Vector2d& b0, const Eigen::Vector2d& b1) {
  const double d1 = Cross(a1 - a0, b0 - a0), d2 = Cross(a1 - a0, b1 - a0);
  const double d3 = Cross(b1 - b0, a0 - b0), d4 = Cross(b1 - b0, a1 - b0);
  const double s = (a1 - a0).norm() * (b1 - b0).norm() * kEps;
  return ((d1 > s && d2 < -s) || (d1 < -s && d2 > s)) &&
         ((d3 > s && d4 < -s) || (d3 < -s && d4 > s));
}

double SignedArea(const std::vector<Eigen::Vector2d>& poly) {
  double a = 0;
  for (size_t i = 0; i < poly.size(); ++i) a += Cross(poly[i], poly[(i + 1) % poly.size()]);
  return 0.5 * a;
}

double BoundaryDistance(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  double d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < poly.size(); ++i)
    d = std::min(d, PointSegmentDistance(p, poly[i], poly[(i + 1) % poly.size()]));
  return d;
}

// Strictly inside (not on the boundary): even-odd ray casting.
bool StrictlyInside(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  if (BoundaryDistance(poly, p) < 1e-6) return false;
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d &a = poly[i], &b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

// The first pair of non-adjacent edges that touch ("" when the polygon is simple).
std::string SelfIntersection(const std::vector<Eigen::Vector2d>& poly) {
  const size_t n = poly.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      const Eigen::Vector2d &a0 = poly[i], &a1 = poly[(i + 1) % n];
      const Eigen::Vector2d &b0 = poly[j], &b1 = poly[(j + 1) % n];
      if (adjacent) {  // adjacent edges share a vertex; they must not fold back over each other
        const Eigen::Vector2d& shared = j == i + 1 ? a1 : a0;
        const Eigen::Vector2d& ea = j == i + 1 ? a0 : a1;
        const Eigen::Vector2d& eb = j == i + 1 ? b1 : b0;
        if (std::abs(Cross(ea - shared, eb - shared)) < kEps && (ea - shared).dot(eb - shared) > 0)
          return "edges " + std::to_string(i) + " and " + std::to_string(j) + " fold back";
        continue;
      }
      if (SegmentsTouch(a0, a1, b0, b1))
        return "edge " + std::to_string(i) + " " + Pt(a0) + "-" + Pt(a1) + " meets edge " +
               std::to_string(j) + " " + Pt(b0) + "-" + Pt(b1);
    }
  }
  return "";
}

const std::vector<std::pair<std::string, SurfaceStyle>>& StyleTable() {
  static const std::vector<std::pair<std::string, SurfaceStyle>> kTable = {
      {"default", SurfaceStyle::kDefault},
      {"plain", SurfaceStyle::kPlain},
      {"busy", SurfaceStyle::kBusy},
      {"bare", SurfaceStyle::kBare},
      {"posters", SurfaceStyle::kPosters}};
  return kTable;
}

// The texture name's prefix for a surface of `kind` ("wall", "floor", "ceiling") in `style`.
std::string TexturePrefix(const std::string& kind, SurfaceStyle style, bool furniture = false) {
  std::string p = style == SurfaceStyle::kPlain ? "plain" + kind : kind;
  if (furniture) p += "-furniture";
  switch (style) {
    case SurfaceStyle::kBusy:
      return p + "-busy";
    case SurfaceStyle::kBare:
      return p + "-bare";
    case SurfaceStyle::kPosters:
      return p + "-posters";
    default:
      return p;
  }
}

bool ValidName(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  return true;
}

// The corridor's polygon (counter-clockwise): right offsets forward, left offsets back.
// Fails on a turn sharper than kMaxTurnDeg or a zero-length segment.
bool CorridorPolygon(const std::vector<Eigen::Vector2d>& c, double width_m,
                     std::vector<Eigen::Vector2d>* poly, std::string* why) {
  const size_t n = c.size();
  std::vector<Eigen::Vector2d> dirs;
  for (size_t i = 0; i + 1 < n; ++i) {
    const Eigen::Vector2d d = c[i + 1] - c[i];
    if (d.norm() < 1e-6) {
      *why = "points " + std::to_string(i) + " and " + std::to_string(i + 1) + " coincide";
      return false;
    }
    dirs.push_back(d.normalized());
  }
  std::vector<Eigen::Vector2d> offset(n);  // left offset of each vertex (mitred)
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d n0 = LeftNormal(dirs[i == 0 ? 0 : i - 1]);
    const Eigen::Vector2d n1 = LeftNormal(dirs[i + 1 == n ? n - 2 : i]);
    const double cos_turn = n0.dot(n1);
    if (cos_turn < std::cos(kMaxTurnDeg * M_PI / 180.0) - 1e-12) {
      *why = "the turn at point " + std::to_string(i) + " " + Pt(c[i]) + " is sharper than " +
             Num(kMaxTurnDeg) + " deg";
      return false;
    }
    offset[i] = 0.5 * width_m * (n0 + n1) / (1.0 + cos_turn);
  }
  poly->clear();
  for (size_t i = 0; i < n; ++i) poly->push_back(c[i] - offset[i]);
  for (size_t i = n; i-- > 0;) poly->push_back(c[i] + offset[i]);
  return true;
}

// Calls item(node, key) on each mapping of the list root[list] (none when absent), its keys
// checked against `keys`; stops at the first error.
template <typename F>
void ForEachItem(YamlReader& r, const YAML::Node& root, const char* list,
                 const std::vector<std::string>& keys, F item) {
  if (!r.ok() || !YamlReader::Has(root, list)) return;
  const YAML::Node l = root[list];
  if (!l.IsSequence()) {
    r.Fail(l, list, "expected a list");
    return;
  }
  for (size_t i = 0; r.ok() && i < l.size(); ++i) {
    const std::string key = YamlReader::Item(list, i);
    if (!r.ExpectMap(l[i], key) || !r.CheckKeys(l[i], key, keys)) return;
    item(l[i], key);
  }
}

// Reads a style key.
void ReadStyle(YamlReader& r, const YAML::Node& map, const std::string& prefix,
               const std::string& key, bool walls, SurfaceStyle* out) {
  r.Enum(map, prefix, key, StyleTable(), out);
  r.Check(walls || *out != SurfaceStyle::kPosters, map, prefix, key,
          "'posters' is a style for walls and boxes only");
}

}  // namespace

double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

bool InsidePolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  return BoundaryDistance(polygon, p) < kEps || StrictlyInside(polygon, p);
}

bool IsFloorPlanPath(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  return ext == ".yaml" || ext == ".yml";
}

bool ParseFloorPlan(const std::string& yaml_text, const std::string& source_name,
                    const std::string& base_dir, FloorPlan* plan, std::string* error) {
  YamlReader r(source_name);
  if (!r.Parse(yaml_text)) return r.Report(error);
  YAML::Node root = r.root();
  FloorPlan p;
  p.source_path = source_name;
  if (!r.ExpectMap(root, "", "a YAML mapping at the top level (a floor plan)"))
    return r.Report(error);
  r.CheckKeys(
      root, "",
      {"name", "ceiling_height_m", "max_door_depth_m", "robot", "floor", "ceiling", "floor_name",
       "ceiling_name", "corridors", "rooms", "doors", "boxes", "lights", "places"});
  r.String(root, "", "name", &p.name, false);
  r.Double(root, "", "ceiling_height_m", &p.ceiling_height_m);
  r.Check(p.ceiling_height_m >= 1.0 && p.ceiling_height_m <= 20.0, root, "", "ceiling_height_m",
          "expected in [1, 20] m, got " + Num(p.ceiling_height_m));
  r.Double(root, "", "max_door_depth_m", &p.max_door_depth_m);
  r.Check(p.max_door_depth_m >= 0 && p.max_door_depth_m <= 2.0, root, "", "max_door_depth_m",
          "expected in [0, 2] m");
  std::string robot = (fs::path(DataDir()) / "scenes" / "robot_p2dx.xml").string();
  if (r.String(root, "", "robot", &robot, false) && YamlReader::Has(root, "robot")) {
    fs::path rp(robot);
    if (rp.is_relative()) rp = fs::path(base_dir) / rp;
    robot = rp.lexically_normal().string();
    r.Check(fs::is_regular_file(robot), root, "", "robot", "file not found: " + robot);
  }
  p.robot_path = robot;
  r.String(root, "", "floor_name", &p.floor_name, false);
  r.Check(p.floor_name.empty() || ValidName(p.floor_name), root, "", "floor_name",
          "expected letters, digits and '_'");
  r.String(root, "", "ceiling_name", &p.ceiling_name, false);
  r.Check(p.ceiling_name.empty() || ValidName(p.ceiling_name), root, "", "ceiling_name",
          "expected letters, digits and '_'");
  ReadStyle(r, root, "", "floor", false, &p.floor);
  ReadStyle(r, root, "", "ceiling", false, &p.ceiling);

  std::map<std::string, int> space_index;
  std::vector<YAML::Node> space_nodes;  // for errors that name a space
  std::vector<std::string> space_keys;
  auto read_space = [&](const YAML::Node& n, const std::string& key, bool corridor) {
    PlanSpace s;
    s.corridor = corridor;
    if (!r.ExpectMap(n, key)) return;
    if (corridor)
      r.CheckKeys(n, key, {"name", "centre", "width_m", "walls", "wall_names"});
    else
      r.CheckKeys(n, key, {"name", "rect", "polygon", "walls", "wall_names"});
    r.Require(n, key, "name", "a name (letters, digits, _)");
    r.String(n, key, "name", &s.name, false);
    r.Check(ValidName(s.name), n, key, "name",
            "expected letters, digits and '_' (at most 64), got '" + s.name + "'");
    r.Check(space_index.count(s.name) == 0, n, key, "name",
            "a second space named '" + s.name + "'");
    ReadStyle(r, n, key, "walls", true, &s.walls);
    if (!r.ok()) return;
    std::string why;
    if (corridor) {
      std::vector<std::pair<double, double>> pts;
      r.Require(n, key, "centre", "the centre line: a list of points [x, y] (m)");
      if (r.ok()) r.ReadPairs(n["centre"], YamlReader::Join(key, "centre"), &pts);
      for (const auto& [x, y] : pts) s.centre.emplace_back(x, y);
      r.Check(!r.ok() || s.centre.size() >= 2, n, key, "centre", "expected at least 2 points");
      r.Require(n, key, "width_m", "the corridor's width (m)");
      r.Double(n, key, "width_m", &s.width_m);
      r.Check(s.width_m > 0.0 && s.width_m <= 50.0, n, key, "width_m",
              "expected a width in (0, 50] m, got " + Num(s.width_m));
      if (!r.ok()) return;
      if (!CorridorPolygon(s.centre, s.width_m, &s.polygon, &why)) {
        r.Fail(n["centre"], YamlReader::Join(key, "centre"), why);
        return;
      }
    } else {
      const bool rect = YamlReader::Has(n, "rect"), poly = YamlReader::Has(n, "polygon");
      r.Check(rect != poly, n, key, rect ? "polygon" : "rect",
              "give a room either rect [x0, y0, x1, y1] or polygon [[x, y], ...]");
      if (!r.ok()) return;
      if (rect) {
        std::vector<double> v;
        r.ReadNumbers(n["rect"], YamlReader::Join(key, "rect"), 4, &v,
                      "a rectangle [x0, y0, x1, y1] (m)");
        if (!r.ok()) return;
        r.Check(v[2] > v[0] && v[3] > v[1], n, key, "rect",
                "expected x1 > x0 and y1 > y0 (a rectangle of non-zero area)");
        s.polygon = {{v[0], v[1]}, {v[2], v[1]}, {v[2], v[3]}, {v[0], v[3]}};
      } else {
        std::vector<std::pair<double, double>> pts;
        r.ReadPairs(n["polygon"], YamlReader::Join(key, "polygon"), &pts);
        for (const auto& [x, y] : pts) s.polygon.emplace_back(x, y);
        r.Check(!r.ok() || s.polygon.size() >= 3, n, key, "polygon", "expected at least 3 points");
        if (!r.ok()) return;
        const double area = SignedArea(s.polygon);
        r.Check(std::abs(area) > 1e-6, n, key, "polygon", "the polygon has no area");
        if (area < 0) std::reverse(s.polygon.begin(), s.polygon.end());
      }
    }
    if (!r.ok()) return;
    why = SelfIntersection(s.polygon);
    if (!why.empty()) {
      const char* k = corridor ? "centre" : YamlReader::Has(n, "rect") ? "rect" : "polygon";
      r.Fail(n[k], YamlReader::Join(key, k),
             std::string(corridor ? "the corridor's walls intersect themselves: "
                                  : "the polygon intersects itself: ") +
                 why);
      return;
    }
    if (YamlReader::Has(n, "wall_names")) {
      const YAML::Node wn = n["wall_names"];
      const std::string wkey = YamlReader::Join(key, "wall_names");
      if (!wn.IsSequence() || wn.size() != s.polygon.size()) {
        r.Fail(wn, wkey,
               "expected a list of " + std::to_string(s.polygon.size()) +
                   " names, one per wall (the polygon's edges in order)");
        return;
      }
      for (size_t i = 0; i < wn.size(); ++i) {
        std::string w;
        if (!r.ReadString(wn[i], YamlReader::Item(wkey, i), &w, false)) return;
        if (!ValidName(w)) {
          r.Fail(wn[i], YamlReader::Item(wkey, i), "expected letters, digits and '_'");
          return;
        }
        s.wall_names.push_back(w);
      }
    }
    space_index[s.name] = static_cast<int>(p.spaces.size());
    space_nodes.push_back(n);
    space_keys.push_back(key);
    p.spaces.push_back(std::move(s));
  };
  for (const char* list : {"corridors", "rooms"}) {
    if (!r.ok() || !YamlReader::Has(root, list)) continue;
    const YAML::Node l = root[list];
    if (!l.IsSequence()) {
      r.Fail(l, list, "expected a list");
      break;
    }
    for (size_t i = 0; i < l.size() && r.ok(); ++i)
      read_space(l[i], YamlReader::Item(list, i), std::string(list) == "corridors");
  }
  if (r.ok() && p.spaces.empty())
    r.Fail(root, "", "a floor plan needs at least one corridor or room");
  // Spaces must not overlap (they may touch: a door joins walls that meet or are close).
  for (size_t a = 0; a < p.spaces.size() && r.ok(); ++a) {
    for (size_t b = a + 1; b < p.spaces.size() && r.ok(); ++b) {
      const auto &pa = p.spaces[a].polygon, &pb = p.spaces[b].polygon;
      bool overlap = false;
      for (size_t i = 0; i < pa.size() && !overlap; ++i)
        for (size_t j = 0; j < pb.size() && !overlap; ++j)
          overlap =
              SegmentsCrossProperly(pa[i], pa[(i + 1) % pa.size()], pb[j], pb[(j + 1) % pb.size()]);
      for (const auto& v : pa) overlap = overlap || StrictlyInside(pb, v);
      for (const auto& v : pb) overlap = overlap || StrictlyInside(pa, v);
      if (overlap)
        r.Fail(space_nodes[b], space_keys[b],
               "space '" + p.spaces[b].name + "' overlaps space '" + p.spaces[a].name +
                   "' (spaces may touch; join them with a door or opening)");
    }
  }

  // Doors.
  ForEachItem(
      r, root, "doors", {"between", "at", "width_m", "height_m"},
      [&](const YAML::Node& n, const std::string& key) {
        r.Require(n, key, "between", "the two spaces it joins [a, b]");
        r.Require(n, key, "at", "the door's centre [x, y] on the wall (m)");
        r.Require(n, key, "width_m", "the door's width (m)");
        if (!r.ok()) return;
        const YAML::Node bn = n["between"];
        const std::string bkey = YamlReader::Join(key, "between");
        if (!bn.IsSequence() || bn.size() != 2) {
          r.Fail(bn, bkey, "expected two space names [a, b]");
          return;
        }
        PlanDoor d;
        std::string names[2];
        for (int k = 0; k < 2 && r.ok(); ++k) {
          r.ReadString(bn[k], YamlReader::Item(bkey, k), &names[k], false);
          if (r.ok() && space_index.count(names[k]) == 0)
            r.Fail(bn[k], YamlReader::Item(bkey, k),
                   "no corridor or room named '" + names[k] + "'");
          if (r.ok()) d.space[k] = space_index[names[k]];
        }
        r.Check(!r.ok() || d.space[0] != d.space[1], n, key, "between",
                "a door joins two different spaces");
        std::vector<double> at;
        r.ReadNumbers(n["at"], YamlReader::Join(key, "at"), 2, &at, "a point [x, y] (m)");
        double width = 0, height = p.ceiling_height_m;
        r.Double(n, key, "width_m", &width);
        r.Check(width > 0, n, key, "width_m", "expected > 0 m, got " + Num(width));
        r.Double(n, key, "height_m", &height);
        r.Check(height > 0 && height <= p.ceiling_height_m, n, key, "height_m",
                "expected in (0, ceiling_height_m = " + Num(p.ceiling_height_m) + "] m");
        r.Check(height == p.ceiling_height_m || p.ceiling_height_m - height >= kMinWallPieceM, n,
                key, "height_m", "leaves a lintel thinner than 1 cm: make it an opening");
        if (!r.ok()) return;
        const Eigen::Vector2d c(at[0], at[1]);
        d.centre_xy = c;
        d.height_m = height;
        // The nearest wall of each space within max_door_depth_m whose span holds the point.
        for (int k = 0; k < 2 && r.ok(); ++k) {
          const auto& poly = p.spaces[d.space[k]].polygon;
          double best = std::numeric_limits<double>::infinity();
          for (size_t e = 0; e < poly.size(); ++e) {
            const Eigen::Vector2d a = poly[e], b = poly[(e + 1) % poly.size()];
            const Eigen::Vector2d dir = (b - a).normalized();
            const double s = (c - a).dot(dir), len = (b - a).norm();
            const double off = -(c - a).dot(LeftNormal(dir));  // outward distance from the wall
            if (s < -kEps || s > len + kEps || off < -p.max_door_depth_m - kEps ||
                off > p.max_door_depth_m + kEps || std::abs(off) >= best)
              continue;
            best = std::abs(off);
            d.edge[k] = static_cast<int>(e);
            d.from_m[k] = s - 0.5 * width;
            d.to_m[k] = s + 0.5 * width;
          }
          if (d.edge[k] < 0)
            r.Fail(n["at"], YamlReader::Join(key, "at"),
                   "the door at " + Pt(c) + " is on no wall of '" + names[k] + "' (within " +
                       Num(p.max_door_depth_m) + " m, max_door_depth_m)");
        }
        if (!r.ok()) return;
        const auto& pa = p.spaces[d.space[0]].polygon;
        const auto& pb = p.spaces[d.space[1]].polygon;
        const Eigen::Vector2d a0 = pa[d.edge[0]], a1 = pa[(d.edge[0] + 1) % pa.size()];
        const Eigen::Vector2d b0 = pb[d.edge[1]], b1 = pb[(d.edge[1] + 1) % pb.size()];
        const Eigen::Vector2d da = (a1 - a0).normalized(), db = (b1 - b0).normalized();
        d.depth_m = -(b0 - a0).dot(LeftNormal(da));
        if (std::abs(Cross(da, db)) > 1e-9 || da.dot(db) > 0) {
          r.Fail(n["at"], YamlReader::Join(key, "at"),
                 "the walls of '" + names[0] + "' and '" + names[1] + "' at " + Pt(c) +
                     " are not parallel and facing: a door joins two facing walls");
          return;
        }
        if (d.depth_m < -kEps || d.depth_m > p.max_door_depth_m + kEps) {
          r.Fail(n["at"], YamlReader::Join(key, "at"),
                 "the walls of '" + names[0] + "' and '" + names[1] + "' are " + Num(d.depth_m) +
                     " m apart; a door joins walls at most max_door_depth_m = " +
                     Num(p.max_door_depth_m) + " m apart");
          return;
        }
        d.depth_m = std::max(0.0, d.depth_m);
        // The span on b's edge: the same points, measured from b's start (b runs the other way).
        const double sb = (c - b0).dot(db);
        d.from_m[1] = sb - 0.5 * width;
        d.to_m[1] = sb + 0.5 * width;
        for (int k = 0; k < 2 && r.ok(); ++k) {
          const auto& poly = p.spaces[d.space[k]].polygon;
          const double len = (poly[(d.edge[k] + 1) % poly.size()] - poly[d.edge[k]]).norm();
          const double left = d.from_m[k], right = len - d.to_m[k];
          if (left < -1e-6 || right < -1e-6) {
            r.Fail(n, key,
                   "the door (" + Num(width) + " m wide at " + Pt(c) +
                       ") runs past the end of wall " + std::to_string(d.edge[k]) + " of '" +
                       names[k] + "' (" + Num(len) + " m long)");
          } else if ((left > 1e-6 && left < kMinWallPieceM) ||
                     (right > 1e-6 && right < kMinWallPieceM)) {
            r.Fail(n, key,
                   "the door leaves a sliver of wall under 1 cm beside it on '" + names[k] +
                       "': put it flush with the wall's end or 1 cm away");
          }
          d.from_m[k] = std::max(0.0, d.from_m[k]);
          d.to_m[k] = std::min(len, d.to_m[k]);
        }
        for (const PlanDoor& o : p.doors) {
          for (int k = 0; k < 2 && r.ok(); ++k)
            for (int q = 0; q < 2; ++q)
              if (o.space[q] == d.space[k] && o.edge[q] == d.edge[k] &&
                  o.from_m[q] < d.to_m[k] - kEps && d.from_m[k] < o.to_m[q] - kEps)
                r.Fail(n, key, "the door overlaps another door on the same wall");
        }
        p.doors.push_back(d);
      });

  // Boxes.
  std::set<std::string> box_names;
  ForEachItem(
      r, root, "boxes", {"name", "at", "yaw_deg", "size_m", "height_m", "sides", "top", "wall"},
      [&](const YAML::Node& n, const std::string& key) {
        PlanBox b;
        r.Require(n, key, "name", "a name (letters, digits, _)");
        r.Require(n, key, "at", "the box's centre [x, y] (m)");
        r.Require(n, key, "size_m", "its sizes [x, y] (m)");
        r.Require(n, key, "height_m", "its height (m)");
        r.String(n, key, "name", &b.name, false);
        r.Check(ValidName(b.name) && box_names.insert(b.name).second, n, key, "name",
                "expected a unique name of letters, digits and '_'");
        std::vector<double> v;
        if (r.ReadNumbers(n["at"], YamlReader::Join(key, "at"), 2, &v, "a point [x, y] (m)"))
          b.centre_xy = Eigen::Vector2d(v[0], v[1]);
        if (r.ReadNumbers(n["size_m"], YamlReader::Join(key, "size_m"), 2, &v, "sizes [x, y] (m)"))
          b.size_m = Eigen::Vector2d(v[0], v[1]);
        r.Check(b.size_m.minCoeff() >= 0.02, n, key, "size_m", "expected sizes >= 0.02 m");
        double yaw_deg = 0;
        r.Double(n, key, "yaw_deg", &yaw_deg);
        b.yaw_rad = yaw_deg * M_PI / 180.0;
        r.Double(n, key, "height_m", &b.height_m);
        r.Check(b.height_m >= 0.02 && b.height_m <= p.ceiling_height_m, n, key, "height_m",
                "expected in [0.02, ceiling_height_m] m");
        ReadStyle(r, n, key, "sides", true, &b.sides);
        ReadStyle(r, n, key, "top", false, &b.top);
        r.Bool(n, key, "wall", &b.wall_like);
        if (!r.ok()) return;
        // Inside the building: every corner in a space, no side through a wall.
        const Eigen::Vector2d ux(std::cos(b.yaw_rad), std::sin(b.yaw_rad));
        const Eigen::Vector2d uy = LeftNormal(ux);
        std::vector<Eigen::Vector2d> corners;
        for (const auto& [sx, sy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
          corners.push_back(b.centre_xy + 0.5 * sx * b.size_m.x() * ux +
                            0.5 * sy * b.size_m.y() * uy);
        for (const auto& q : corners) {
          bool in = false;
          for (const auto& s : p.spaces) in = in || InsidePolygon(s.polygon, q);
          if (!in) {
            r.Fail(n, key, "the box's corner " + Pt(q) + " is outside every corridor and room");
            return;
          }
        }
        for (size_t k = 0; k < 4 && r.ok(); ++k)
          for (const auto& s : p.spaces)
            for (size_t e = 0; e < s.polygon.size() && r.ok(); ++e)
              if (SegmentsCrossProperly(corners[k], corners[(k + 1) % 4], s.polygon[e],
                                        s.polygon[(e + 1) % s.polygon.size()]))
                r.Fail(n, key,
                       "the box crosses wall " + std::to_string(e) + " of '" + s.name + "'");
        p.boxes.push_back(b);
      });

  // Lights: the hand-written hallways' two directional lights unless given.
  if (r.ok() && YamlReader::Has(root, "lights")) {
    const YAML::Node l = root["lights"];
    if (!l.IsSequence() || l.size() < 1 || l.size() > 8)
      r.Fail(l, "lights", "expected a list of 1 to 8 lights");
    for (size_t i = 0; r.ok() && i < l.size(); ++i) {
      const YAML::Node n = l[i];
      const std::string key = YamlReader::Item("lights", i);
      if (!r.ExpectMap(n, key)) break;
      r.CheckKeys(n, key, {"type", "pos", "dir", "diffuse", "cutoff_deg"});
      PlanLight li;
      std::string type = "directional";
      r.String(n, key, "type", &type);
      r.Check(type == "directional" || type == "point", n, key, "type",
              "expected 'directional' or 'point', got '" + type + "'");
      li.directional = type == "directional";
      std::vector<double> v;
      if (YamlReader::Has(n, "pos") &&
          r.ReadNumbers(n["pos"], YamlReader::Join(key, "pos"), 3, &v, "a point [x, y, z] (m)"))
        li.pos = Eigen::Vector3d(v[0], v[1], v[2]);
      if (YamlReader::Has(n, "dir") &&
          r.ReadNumbers(n["dir"], YamlReader::Join(key, "dir"), 3, &v, "a direction [x, y, z]"))
        li.dir = Eigen::Vector3d(v[0], v[1], v[2]);
      r.Check(li.dir.norm() > 1e-6, n, key, "dir", "expected a non-zero direction");
      r.Double(n, key, "diffuse", &li.diffuse);
      r.Check(li.diffuse >= 0 && li.diffuse <= 1, n, key, "diffuse", "expected in [0, 1]");
      if (YamlReader::Has(n, "cutoff_deg")) {
        r.Check(!li.directional, n, key, "cutoff_deg", "only a point light has a cone");
        r.Double(n, key, "cutoff_deg", &li.cutoff_deg);
        r.Check(li.cutoff_deg > 0 && li.cutoff_deg <= 90, n, key, "cutoff_deg",
                "expected an angle in (0, 90] degrees");
      }
      p.lights.push_back(li);
    }
  } else {
    PlanLight a, b;
    a.dir = Eigen::Vector3d(0.3, 0.2, -1);
    b.dir = Eigen::Vector3d(-0.3, -0.4, -0.6);
    b.diffuse = 0.12;
    p.lights = {a, b};
  }

  // Places: name -> [x, y] inside a space.
  if (r.ok() && YamlReader::Has(root, "places")) {
    const YAML::Node m = root["places"];
    if (r.ExpectMap(m, "places", "a mapping name: [x, y]")) {
      for (auto it = m.begin(); it != m.end() && r.ok(); ++it) {
        const std::string name = it->first.as<std::string>();
        const std::string key = YamlReader::Join("places", name);
        std::vector<double> v;
        if (!r.ReadNumbers(it->second, key, 2, &v, "a point [x, y] (m)")) break;
        const Eigen::Vector2d q(v[0], v[1]);
        bool in = false;
        for (const auto& s : p.spaces) in = in || StrictlyInside(s.polygon, q);
        if (!ValidName(name))
          r.Fail(it->first, key, "expected a name of letters, digits and '_'");
        else if (!in)
          r.Fail(it->second, key, "the place " + Pt(q) + " is inside no corridor or room");
        p.places.emplace_back(name, q);
      }
    }
  }
  if (p.name.empty()) p.name = fs::path(source_name).stem().string();
  if (r.ok()) {
    std::set<std::string> textures;
    for (const PlanSurface& surface : PlanSurfaces(p)) textures.insert(surface.texture);
    r.Check(textures.size() <= static_cast<size_t>(kMaxPlanTextures), root, "", "",
            "the plan needs " + std::to_string(textures.size()) + " textures (one per wall " +
                "piece, door reveal, box side pair and top); MuJoCo's renderer holds at most " +
                std::to_string(kMaxPlanTextures) + ": fewer doors, boxes or walls");
  }
  if (!r.Report(error)) return false;
  *plan = std::move(p);
  return true;
}

bool LoadFloorPlan(const std::string& path, FloorPlan* plan, std::string* error) {
  std::string text;
  if (!ReadInputFile(path, "floor-plan YAML file", &text, error)) return false;
  return ParseFloorPlan(text, path, fs::absolute(path).parent_path().string(), plan, error);
}

std::vector<PlanSurface> PlanSurfaces(const FloorPlan& plan) {
  std::vector<PlanSurface> out;
  const double h = plan.ceiling_height_m;
  // A vertical plane from a to b (seen with a on the right, b on the left: its normal is the
  // left normal of b - a), z from z0 to z1.
  auto vertical = [&](const std::string& name, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                      double z0, double z1) {
    const Eigen::Vector2d d = (b - a).normalized();
    PlanSurface s;
    s.name = name;
    s.texture = name;
    s.centre = Eigen::Vector3d(0.5 * (a.x() + b.x()), 0.5 * (a.y() + b.y()), 0.5 * (z0 + z1));
    s.x_axis = Eigen::Vector3d(-d.x(), -d.y(), 0);
    s.y_axis = Eigen::Vector3d::UnitZ();
    s.half_width_m = 0.5 * (b - a).norm();
    s.half_height_m = 0.5 * (z1 - z0);
    s.px_per_m = kWallPxPerM;
    out.push_back(s);
  };
  // Walls, cut at the doors.
  for (size_t si = 0; si < plan.spaces.size(); ++si) {
    const PlanSpace& sp = plan.spaces[si];
    const std::string prefix = TexturePrefix("wall", sp.walls);
    for (size_t e = 0; e < sp.polygon.size(); ++e) {
      const Eigen::Vector2d a = sp.polygon[e], b = sp.polygon[(e + 1) % sp.polygon.size()];
      const double len = (b - a).norm();
      const Eigen::Vector2d d = (b - a) / len;
      const std::string label =
          sp.wall_names.empty() ? sp.name + "_" + std::to_string(e) : sp.wall_names[e];
      std::vector<std::pair<double, double>> gaps;  // (from, to) along the edge
      std::vector<double> tops;                     // each gap's door height
      for (const PlanDoor& door : plan.doors)
        for (int k = 0; k < 2; ++k)
          if (door.space[k] == static_cast<int>(si) && door.edge[k] == static_cast<int>(e)) {
            gaps.emplace_back(door.from_m[k], door.to_m[k]);
            tops.push_back(door.height_m);
          }
      if (gaps.empty()) {
        vertical(prefix + "_" + label, a, b, 0.0, h);
        continue;
      }
      std::vector<size_t> order(gaps.size());
      for (size_t k = 0; k < order.size(); ++k) order[k] = k;
      std::sort(order.begin(), order.end(),
                [&](size_t x, size_t y) { return gaps[x].first < gaps[y].first; });
      double s = 0.0;
      int piece = 0;
      for (size_t k : order) {
        if (gaps[k].first - s > kEps)
          vertical(prefix + "_" + label + "_" + std::to_string(piece++), a + s * d,
                   a + gaps[k].first * d, 0.0, h);
        if (h - tops[k] > kEps)
          vertical(prefix + "_" + label + "_" + std::to_string(piece++), a + gaps[k].first * d,
                   a + gaps[k].second * d, tops[k], h);
        s = gaps[k].second;
      }
      if (len - s > kEps)
        vertical(prefix + "_" + label + "_" + std::to_string(piece++), a + s * d, b, 0.0, h);
    }
  }
  // Door reveals: jambs facing into the passage, a soffit facing down.
  for (size_t i = 0; i < plan.doors.size(); ++i) {
    const PlanDoor& door = plan.doors[i];
    if (door.depth_m <= kEps) continue;
    const PlanSpace& sp = plan.spaces[door.space[0]];
    const Eigen::Vector2d a = sp.polygon[door.edge[0]];
    const Eigen::Vector2d d = (sp.polygon[(door.edge[0] + 1) % sp.polygon.size()] - a).normalized();
    const Eigen::Vector2d out_dir = -LeftNormal(d) * door.depth_m;
    const Eigen::Vector2d p0 = a + door.from_m[0] * d, p1 = a + door.to_m[0] * d;
    const std::string prefix = TexturePrefix("wall", sp.walls, true) + "_door" + std::to_string(i);
    vertical(prefix + "_jamb0", p0, p0 + out_dir, 0.0, door.height_m);
    vertical(prefix + "_jamb1", p1 + out_dir, p1, 0.0, door.height_m);
    out[out.size() - 2].texture = out.back().texture = prefix + "_jamb";  // the same size
    if (h - door.height_m > kEps) {
      PlanSurface s;
      s.name = TexturePrefix("ceiling", SurfaceStyle::kPlain) + "_door" + std::to_string(i);
      s.texture = s.name;
      const Eigen::Vector2d c = 0.5 * (p0 + p1) + 0.5 * out_dir;
      s.centre = Eigen::Vector3d(c.x(), c.y(), door.height_m);
      s.x_axis = Eigen::Vector3d(d.x(), d.y(), 0);
      const Eigen::Vector2d n = out_dir.normalized();
      s.y_axis = Eigen::Vector3d(n.x(), n.y(), 0);  // x × y points down for a left-handed pair
      if (s.x_axis.cross(s.y_axis).z() > 0) s.y_axis = -s.y_axis;
      s.half_width_m = 0.5 * (p1 - p0).norm();
      s.half_height_m = 0.5 * door.depth_m;
      s.px_per_m = kWallPxPerM;
      out.push_back(s);
    }
  }
  // Floor and ceiling over the bounding box.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const PlanSpace& sp : plan.spaces)
    for (const auto& q : sp.polygon) {
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  const Eigen::Vector2d mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
  PlanSurface f;
  f.name = TexturePrefix("floor", plan.floor) + "_" +
           (plan.floor_name.empty() ? plan.name : plan.floor_name);
  f.texture = f.name;
  f.centre = Eigen::Vector3d(mid.x(), mid.y(), 0.0);
  f.half_width_m = half.x();
  f.half_height_m = half.y();
  f.px_per_m = kFloorPxPerM;
  out.push_back(f);
  PlanSurface c = f;
  c.name = TexturePrefix("ceiling", plan.ceiling) + "_" +
           (plan.ceiling_name.empty() ? plan.name : plan.ceiling_name);
  c.texture = c.name;
  c.centre.z() = h;
  c.y_axis = -Eigen::Vector3d::UnitY();
  c.px_per_m = kCeilingPxPerM;
  out.push_back(c);
  // Boxes: sides facing out (corners clockwise, so the left normal points out), then the top.
  for (const PlanBox& b : plan.boxes) {
    const Eigen::Vector2d ux(std::cos(b.yaw_rad), std::sin(b.yaw_rad)), uy = LeftNormal(ux);
    const Eigen::Vector2d hx = 0.5 * b.size_m.x() * ux, hy = 0.5 * b.size_m.y() * uy;
    const Eigen::Vector2d q[4] = {b.centre_xy - hx - hy, b.centre_xy - hx + hy,
                                  b.centre_xy + hx + hy, b.centre_xy + hx - hy};
    const std::string prefix = TexturePrefix("wall", b.sides, !b.wall_like) + "_box_" + b.name;
    for (int k = 0; k < 4; ++k) {
      vertical(prefix + "_" + std::to_string(k), q[k], q[(k + 1) % 4], 0.0, b.height_m);
      out.back().texture = prefix + "_" + std::to_string(k % 2);  // opposite sides share
    }
    if (b.height_m >= h - kEps) continue;  // up to the ceiling: no top (it would lie in it)
    PlanSurface t;
    t.name = TexturePrefix("floor", b.top) + "_box_" + b.name + "_top";
    t.texture = t.name;
    t.centre = Eigen::Vector3d(b.centre_xy.x(), b.centre_xy.y(), b.height_m);
    t.x_axis = Eigen::Vector3d(ux.x(), ux.y(), 0);
    t.y_axis = Eigen::Vector3d(uy.x(), uy.y(), 0);
    t.half_width_m = 0.5 * b.size_m.x();
    t.half_height_m = 0.5 * b.size_m.y();
    t.px_per_m = kWallPxPerM;
    out.push_back(t);
  }
  return out;
}

std::vector<PlanSolid> PlanSolids(const FloorPlan& plan) {
  const std::vector<PlanSurface> surfaces = PlanSurfaces(plan);
  // The surfaces of the boxes come last: four sides and a top unless the box is as high as the
  // ceiling; floor and ceiling before them. Walls, jambs and soffits before those.
  size_t box_surfaces = 0;
  for (const PlanBox& b : plan.boxes)
    box_surfaces += b.height_m >= plan.ceiling_height_m - kEps ? 4 : 5;
  const size_t walls_end = surfaces.size() - box_surfaces - 2;
  struct Vertical {
    const PlanSurface* s;
    Eigen::Vector2d a, b, n;  // its ends and its normal (into the space it faces)
  };
  std::vector<Vertical> vertical;
  for (size_t i = 0; i < walls_end; ++i) {
    const PlanSurface& s = surfaces[i];
    if (std::abs(s.y_axis.z()) < 0.5) continue;  // a soffit: above the robot
    const Eigen::Vector2d c = s.centre.head<2>(), x = s.x_axis.head<2>();
    vertical.push_back({&s, c - s.half_width_m * x, c + s.half_width_m * x,
                        s.x_axis.cross(s.y_axis).head<2>().normalized()});
  }
  std::vector<PlanSolid> out;
  for (const Vertical& v : vertical) {
    // As thick as kSolidThicknessM, but no more than half the gap to a wall facing the other way
    // behind it (two spaces 0.1 m apart get 0.05 m each; coincident walls kMinSolidThicknessM).
    double t = kSolidThicknessM;
    const Eigen::Vector2d along = (v.b - v.a).normalized();
    const double len = (v.b - v.a).norm();
    for (const Vertical& w : vertical) {
      if (&w == &v || v.n.dot(w.n) > -1.0 + 1e-6) continue;  // not antiparallel
      const double gap = (v.a - w.a).dot(v.n);               // w behind v by this much
      if (gap < -kEps || gap >= 2.0 * t) continue;
      const double s0 = (w.a - v.a).dot(along), s1 = (w.b - v.a).dot(along);
      if (std::max(s0, s1) <= kEps || std::min(s0, s1) >= len - kEps) continue;  // no overlap
      t = std::max(kMinSolidThicknessM, std::min(t, 0.5 * gap));
    }
    PlanSolid s;
    s.name = "solid_" + v.s->name;
    s.centre = v.s->centre - 0.5 * t * Eigen::Vector3d(v.n.x(), v.n.y(), 0.0);
    s.x_axis = v.s->x_axis;
    s.y_axis = v.s->y_axis;
    s.half_size = Eigen::Vector3d(v.s->half_width_m, v.s->half_height_m, 0.5 * t);
    out.push_back(s);
  }
  for (const PlanBox& b : plan.boxes) {
    PlanSolid s;
    s.name = "solid_box_" + b.name;
    s.centre = Eigen::Vector3d(b.centre_xy.x(), b.centre_xy.y(), 0.5 * b.height_m);
    s.x_axis = Eigen::Vector3d(std::cos(b.yaw_rad), std::sin(b.yaw_rad), 0.0);
    s.y_axis = Eigen::Vector3d(-std::sin(b.yaw_rad), std::cos(b.yaw_rad), 0.0);
    s.half_size = Eigen::Vector3d(0.5 * b.size_m.x(), 0.5 * b.size_m.y(), 0.5 * b.height_m);
    out.push_back(s);
  }
  return out;
}

std::string FloorPlanToMjcf(const FloorPlan& plan, const std::string& robot_include, bool solids) {
  const std::vector<PlanSurface> surfaces = PlanSurfaces(plan);
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const PlanSpace& sp : plan.spaces)
    for (const auto& q : sp.polygon) {
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  const double zfar = std::max(40.0, std::ceil((hi - lo).norm() + plan.ceiling_height_m + 5.0));
  std::ostringstream x;
  x << "<!-- Generated by vobench from the floor plan "
    << (plan.source_path.empty() ? plan.name : fs::path(plan.source_path).filename().string())
    << " (sim/floor_plan.h, scenes/README.md): walls mitred at the corners, cut at the doors,\n"
       "     one floor and one ceiling plane; every plane's texture is generated from its name. "
       "-->\n";
  x << "<mujoco model=\"" << plan.name << "\">\n";
  x << "  <compiler angle=\"degree\"/>\n";
  x << "  <option timestep=\"0.002\" integrator=\"implicit\"/>\n";
  x << "  <statistic extent=\"1\" center=\"" << Num(0.5 * (lo.x() + hi.x())) << " "
    << Num(0.5 * (lo.y() + hi.y())) << " 1\"/>\n";
  x << "  <visual>\n"
       "    <global offwidth=\"640\" offheight=\"480\"/>\n"
       "    <headlight active=\"0\" ambient=\"0 0 0\" diffuse=\"0 0 0\" specular=\"0 0 0\"/>\n"
       "    <map znear=\"0.02\" zfar=\""
    << Num(zfar)
    << "\"/>\n"
       "    <quality shadowsize=\"0\" offsamples=\"4\"/>\n"
       "  </visual>\n";
  x << "  <asset>\n";
  std::set<std::string> written;
  for (const PlanSurface& s : surfaces) {
    if (!written.insert(s.texture).second) continue;
    const long w = std::max(1L, std::lround(2.0 * s.half_width_m * s.px_per_m));
    const long hgt = std::max(1L, std::lround(2.0 * s.half_height_m * s.px_per_m));
    x << "    <texture name=\"" << s.texture
      << "\" type=\"2d\" builtin=\"flat\" rgb1=\"0.5 0.5 0.5\" "
      << "width=\"" << w << "\" height=\"" << hgt << "\"/>\n";
    x << "    <material name=\"" << s.texture << "\" texture=\"" << s.texture
      << "\" texrepeat=\"1 1\" emission=\"0.75\" specular=\"0\" shininess=\"0\" "
         "reflectance=\"0\"/>\n";
  }
  x << "  </asset>\n";
  x << "  <include file=\"" << robot_include << "\"/>\n";
  x << "  <worldbody>\n";
  for (const PlanLight& l : plan.lights) {
    x << "    <light directional=\"" << (l.directional ? "true" : "false") << "\" pos=\""
      << Num(l.pos.x()) << " " << Num(l.pos.y()) << " " << Num(l.pos.z()) << "\" dir=\""
      << Num(l.dir.x()) << " " << Num(l.dir.y()) << " " << Num(l.dir.z()) << "\" diffuse=\""
      << Num(l.diffuse) << " " << Num(l.diffuse) << " " << Num(l.diffuse) << "\"";
    if (l.cutoff_deg > 0) x << " cutoff=\"" << Num(l.cutoff_deg) << "\"";
    x << " specular=\"0 0 0\" castshadow=\"false\"/>\n";
  }
  x << "    <!-- physics floor: infinite, collision only (group 3 is never drawn) -->\n";
  x << "    <geom name=\"physics_floor\" type=\"plane\" size=\"0 0 1\" group=\"3\" "
       "rgba=\"0 0 0 0\" friction=\"1 0.005 0.0001\"/>\n";
  for (const PlanSurface& s : surfaces) {
    x << "    <geom name=\"" << s.name << "\" type=\"plane\" size=\"" << Num(s.half_width_m) << " "
      << Num(s.half_height_m) << " 0.1\" pos=\"" << Num(s.centre.x()) << " " << Num(s.centre.y())
      << " " << Num(s.centre.z()) << "\" xyaxes=\"" << Num(s.x_axis.x()) << " " << Num(s.x_axis.y())
      << " " << Num(s.x_axis.z()) << " " << Num(s.y_axis.x()) << " " << Num(s.y_axis.y()) << " "
      << Num(s.y_axis.z()) << "\" material=\"" << s.texture
      << "\" contype=\"0\" conaffinity=\"0\" group=\"0\"/>\n";
  }
  if (solids) {
    x << "    <!-- The building's solid side, collision only (group 3 is never drawn): a box "
         "behind "
         "each wall\n         piece and jamb, and each box itself, so that a robot meets them "
         "(navigation: vo). -->\n";
    for (const PlanSolid& s : PlanSolids(plan)) {
      x << "    <geom name=\"" << s.name << "\" type=\"box\" size=\"" << Num(s.half_size.x()) << " "
        << Num(s.half_size.y()) << " " << Num(s.half_size.z()) << "\" pos=\"" << Num(s.centre.x())
        << " " << Num(s.centre.y()) << " " << Num(s.centre.z()) << "\" xyaxes=\""
        << Num(s.x_axis.x()) << " " << Num(s.x_axis.y()) << " " << Num(s.x_axis.z()) << " "
        << Num(s.y_axis.x()) << " " << Num(s.y_axis.y()) << " " << Num(s.y_axis.z())
        << "\" group=\"3\" rgba=\"0 0 0 0\"/>\n";
    }
  }
  x << "  </worldbody>\n</mujoco>\n";
  return x.str();
}

namespace {

// The plan's obstacles for a path (vertical surfaces reaching below 1.5 m) and its free area.
struct FreeSpace {
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> obstacles;
  std::vector<std::vector<Eigen::Vector2d>> areas;  // spaces and door passages
  double clearance_m = 0.0;

  explicit FreeSpace(const FloorPlan& plan, double clearance) : clearance_m(clearance) {
    for (const PlanSurface& s : PlanSurfaces(plan)) {
      if (std::abs(s.y_axis.z()) < 0.5 || s.centre.z() - s.half_height_m > 1.5) continue;
      const Eigen::Vector2d c = s.centre.head<2>(), x = s.x_axis.head<2>();
      obstacles.emplace_back(c - s.half_width_m * x, c + s.half_width_m * x);
    }
    for (const PlanSpace& sp : plan.spaces) areas.push_back(sp.polygon);
    for (const PlanDoor& d : plan.doors) {  // the passage between the two walls
      const auto& poly = plan.spaces[d.space[0]].polygon;
      const Eigen::Vector2d a = poly[d.edge[0]];
      const Eigen::Vector2d dir = (poly[(d.edge[0] + 1) % poly.size()] - a).normalized();
      const Eigen::Vector2d out = -LeftNormal(dir) * d.depth_m;
      const Eigen::Vector2d p0 = a + d.from_m[0] * dir, p1 = a + d.to_m[0] * dir;
      if (d.depth_m > kEps) areas.push_back({p0, p0 + out, p1 + out, p1});
    }
  }
  bool Inside(const Eigen::Vector2d& p) const {
    for (const auto& a : areas)
      if (InsidePolygon(a, p)) return true;
    return false;
  }
  bool Free(const Eigen::Vector2d& p) const {
    for (const auto& [a, b] : obstacles)
      if (PointSegmentDistance(p, a, b) < clearance_m) return false;
    return Inside(p);
  }
  // The straight segment keeps the clearance (exactly) and stays inside (every 2 cm).
  bool Clear(const Eigen::Vector2d& p, const Eigen::Vector2d& q) const {
    for (const auto& [a, b] : obstacles) {
      const bool cross = SegmentsCrossProperly(p, q, a, b);
      const double d = std::min({PointSegmentDistance(p, a, b), PointSegmentDistance(q, a, b),
                                 PointSegmentDistance(a, p, q), PointSegmentDistance(b, p, q)});
      if (cross || d < clearance_m) return false;
    }
    const int n = std::max(1, static_cast<int>(std::ceil((q - p).norm() / 0.02)));
    for (int k = 0; k <= n; ++k)
      if (!Inside(p + (q - p) * (static_cast<double>(k) / n))) return false;
    return true;
  }
};

}  // namespace

bool PlanPath(const FloorPlan& plan, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
              double clearance_m, std::vector<Eigen::Vector2d>* path, std::string* error,
              double cell_m) {
  const FreeSpace free(plan, clearance_m);
  const Eigen::Vector2d ends[2] = {from, to};
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector2d& p = ends[k];
    if (!free.Free(p)) {
      *error = std::string("the ") + (k == 0 ? "start" : "goal") + " " + Pt(p) +
               " is not in free space (inside the " + "building and " + Num(clearance_m) +
               " m from every wall and box)";
      return false;
    }
  }
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const auto& a : free.areas)
    for (const auto& q : a) {
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  const int nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell_m)) + 1;
  const int ny = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell_m)) + 1;
  auto centre = [&](int i) -> Eigen::Vector2d {
    return lo + cell_m * Eigen::Vector2d(i % nx, i / nx);
  };
  auto cell_of = [&](const Eigen::Vector2d& p) {
    const int cx = std::clamp(static_cast<int>(std::lround((p.x() - lo.x()) / cell_m)), 0, nx - 1);
    const int cy = std::clamp(static_cast<int>(std::lround((p.y() - lo.y()) / cell_m)), 0, ny - 1);
    return cy * nx + cx;
  };
  std::vector<signed char> is_free(static_cast<size_t>(nx) * ny, -1);  // -1: not yet known
  auto cell_free = [&](int i) {
    if (is_free[i] < 0) is_free[i] = free.Free(centre(i)) ? 1 : 0;
    return is_free[i] == 1;
  };
  const int start = cell_of(from), goal = cell_of(to);
  // The ends join the grid at their nearest cells; those must be reachable in a straight line.
  if (!cell_free(start) || !cell_free(goal) || !free.Clear(from, centre(start)) ||
      !free.Clear(centre(goal), to)) {
    *error =
        "the start or the goal is too close to a wall for the planner's " + Num(cell_m) + " m grid";
    return false;
  }
  // A*, ties broken by the cell index (deterministic).
  std::vector<double> g(is_free.size(), std::numeric_limits<double>::infinity());
  std::vector<int> parent(is_free.size(), -1);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  g[start] = 0;
  open.push({(centre(start) - centre(goal)).norm(), start});
  while (!open.empty()) {
    const auto [f, i] = open.top();
    open.pop();
    if (i == goal) break;
    if (f > g[i] + (centre(i) - centre(goal)).norm() + 1e-12) continue;  // stale
    const int cx = i % nx, cy = i / nx;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = cx + dx, y = cy + dy;
        if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= nx || y >= ny) continue;
        const int j = y * nx + x;
        if (!cell_free(j)) continue;
        const double step = cell_m * ((dx != 0 && dy != 0) ? M_SQRT2 : 1.0);
        if (g[i] + step < g[j] - 1e-12) {
          g[j] = g[i] + step;
          parent[j] = i;
          open.push({g[j] + (centre(j) - centre(goal)).norm(), j});
        }
      }
    }
  }
  if (!std::isfinite(g[goal])) {
    *error = "no path from " + Pt(from) + " to " + Pt(to) + " keeps " + Num(clearance_m) +
             " m from the walls (a door narrower than " + Num(2 * clearance_m) + " m?)";
    return false;
  }
  std::vector<Eigen::Vector2d> cells;  // start .. goal
  for (int i = goal; i >= 0; i = parent[i]) cells.push_back(centre(i));
  std::reverse(cells.begin(), cells.end());
  cells.front() = from;
  if (cells.size() == 1)
    cells.push_back(to);
  else
    cells.back() = to;
  // Shortened: the farthest point in sight, each time.
  path->assign(1, from);
  size_t at = 0;
  while (at + 1 < cells.size()) {
    size_t next = at + 1;
    for (size_t k = cells.size() - 1; k > at + 1; --k) {
      if (free.Clear(cells[at], cells[k])) {
        next = k;
        break;
      }
    }
    path->push_back(cells[next]);
    at = next;
  }
  return true;
}

namespace {

// `extra` inserted before the last "</mujoco>" of `xml`: false when there is none.
bool AddToMujoco(std::string* xml, const std::string& extra) {
  if (extra.empty()) return true;
  const size_t end = xml->rfind("</mujoco>");
  if (end == std::string::npos) return false;
  xml->insert(end, extra);
  return true;
}

}  // namespace

mjModel* LoadSceneModel(const std::string& scene_path, std::string* error,
                        const std::string& extra_mjcf) {
  char load_error[1024] = "";
  if (!IsFloorPlanPath(scene_path) && extra_mjcf.empty()) {
    mjModel* m = mj_loadXML(scene_path.c_str(), nullptr, load_error, sizeof(load_error));
    if (!m) *error = scene_path + ": cannot load MJCF scene: " + load_error;
    return m;
  }
  std::vector<std::pair<std::string, std::string>> files;  // VFS name, text
  std::string load_name;  // what mj_loadXML opens: its folder is where includes are looked up
  if (!IsFloorPlanPath(scene_path)) {
    std::string xml;
    if (!ReadInputFile(scene_path, "MJCF scene", &xml, error)) return nullptr;
    if (!AddToMujoco(&xml, extra_mjcf)) {
      *error = scene_path + ": cannot load MJCF scene: no </mujoco> element";
      return nullptr;
    }
    const std::filesystem::path p(scene_path);
    const std::string name = "vobench_with_people_" + p.filename().string();
    load_name = (p.parent_path() / name).string();
    files.emplace_back(name, xml);
  } else {
    FloorPlan plan;
    if (!LoadFloorPlan(scene_path, &plan, error)) return nullptr;
    std::string robot;
    if (!ReadInputFile(plan.robot_path, "robot MJCF file", &robot, error)) return nullptr;
    // MuJoCo's virtual file system holds the generated scene and the robot it includes.
    const std::string scene_name = "vobench_floor_plan_scene.xml";
    const std::string robot_name = "vobench_floor_plan_robot.xml";
    std::string xml = FloorPlanToMjcf(plan, robot_name);
    AddToMujoco(&xml, extra_mjcf);
    files = {{scene_name, xml}, {robot_name, robot}};
    load_name = scene_name;
  }
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  for (const auto& [name, text] : files) {
    if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(text.size())) != 0) {
      *error = scene_path + ": cannot hold the generated scene in MuJoCo's virtual file system";
      mj_deleteVFS(vfs.get());
      return nullptr;
    }
    const int i = mj_findFileVFS(vfs.get(), name.c_str());
    std::memcpy(vfs->filedata[i], text.data(), text.size());
  }
  mjModel* m = mj_loadXML(load_name.c_str(), vfs.get(), load_error, sizeof(load_error));
  mj_deleteVFS(vfs.get());
  if (!m)
    *error =
        scene_path +
        (IsFloorPlanPath(scene_path) ? ": the scene generated from the floor plan does not load: "
                                     : ": cannot load MJCF scene: ") +
        load_error;
  return m;
}

}  // namespace sim
