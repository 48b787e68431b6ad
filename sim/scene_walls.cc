#include "sim/scene_walls.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "sim/floor_plan.h"
#include "sim/path_follower.h"

namespace sim {
namespace {

namespace fs = std::filesystem;

// |z| of a unit axis below this: horizontal; above 1 - this: vertical.
constexpr double kAxisTolerance = 1e-3;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// 2-D cross product.
double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

std::string Point(const Eigen::Vector2d& p) {
  std::ostringstream s;
  s << "(" << p.x() << ", " << p.y() << ")";
  return s.str();
}

}  // namespace

void WallsOfModel(const mjModel* m, std::vector<SceneWall>* walls,
                  std::vector<SceneFloor>* floors) {
  mjData* d = mj_makeData(m);
  mj_kinematics(m, d);  // geom_xpos, geom_xmat
  walls->clear();
  if (floors) floors->clear();
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_type[g] != mjGEOM_PLANE || m->body_weldid[m->geom_bodyid[g]] != 0) continue;
    const mjtNum* R = d->geom_xmat + 9 * g;  // row-major; columns are the geom's axes
    const Eigen::Vector3d x(R[0], R[3], R[6]), y(R[1], R[4], R[7]), normal(R[2], R[5], R[8]);
    const mjtNum* size = m->geom_size + 3 * g;
    if (floors && normal.z() > 1 - kAxisTolerance && size[0] > 0 && size[1] > 0) {
      SceneFloor f;
      f.centre_xy = Eigen::Vector2d(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1]);
      f.axis_xy[0] = x.head<2>().normalized();
      f.axis_xy[1] = y.head<2>().normalized();
      f.half_size_m[0] = size[0];
      f.half_size_m[1] = size[1];
      floors->push_back(f);
      continue;
    }
    if (std::abs(normal.z()) > kAxisTolerance) continue;  // floor, ceiling, a tilted plane
    int horizontal = -1;
    if (std::abs(x.z()) < kAxisTolerance && std::abs(y.z()) > 1 - kAxisTolerance) horizontal = 0;
    if (std::abs(y.z()) < kAxisTolerance && std::abs(x.z()) > 1 - kAxisTolerance) horizontal = 1;
    if (horizontal < 0) continue;  // rotated within its plane: not a wall for this check
    const Eigen::Vector3d& along = horizontal == 0 ? x : y;
    const double half_along = size[horizontal], half_up = size[1 - horizontal];
    SceneWall w;
    const char* name = mj_id2name(m, mjOBJ_GEOM, g);
    w.name = name ? name : "";
    w.centre_xy = Eigen::Vector2d(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1]);
    w.along_xy = along.head<2>().normalized();
    w.half_length_m = half_along > 0 ? half_along : kInfinity;  // size 0: infinite plane
    const double z = d->geom_xpos[3 * g + 2];
    w.z_min_m = half_up > 0 ? z - half_up : -kInfinity;
    w.z_max_m = half_up > 0 ? z + half_up : kInfinity;
    walls->push_back(w);
  }
  mj_deleteData(d);
}

bool WallsOfScene(const std::string& scene_path, std::vector<SceneWall>* walls, std::string* error,
                  std::vector<SceneFloor>* floors) {
  mjModel* m = LoadSceneModel(scene_path, error);  // MJCF or a floor plan
  if (!m) return false;
  WallsOfModel(m, walls, floors);
  mj_deleteModel(m);
  return true;
}

namespace {

// Where segments a0-a1 and b0-b1 cross (the parameter along a in *t), if they do.
bool SegmentsCross(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1, const Eigen::Vector2d& b0,
                   const Eigen::Vector2d& b1, double* t) {
  const Eigen::Vector2d r = a1 - a0, q = b1 - b0;
  const double denom = Cross(r, q);
  if (std::abs(denom) < 1e-12) return false;  // parallel
  const Eigen::Vector2d w = b0 - a0;
  *t = Cross(w, q) / denom;
  const double u = Cross(w, r) / denom;
  return *t >= 0 && *t <= 1 && u >= 0 && u <= 1;
}

double SegmentDistance(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1,
                       const Eigen::Vector2d& b0, const Eigen::Vector2d& b1) {
  double t = 0;
  if (SegmentsCross(a0, a1, b0, b1, &t)) return 0.0;
  return std::min({PointSegmentDistance(a0, b0, b1), PointSegmentDistance(a1, b0, b1),
                   PointSegmentDistance(b0, a0, a1), PointSegmentDistance(b1, a0, a1)});
}

bool InTriangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                const Eigen::Vector2d& c) {
  const double d1 = Cross(b - a, p - a), d2 = Cross(c - b, p - b), d3 = Cross(a - c, p - c);
  return (d1 >= 0 && d2 >= 0 && d3 >= 0) || (d1 <= 0 && d2 <= 0 && d3 <= 0);
}

bool OverFloor(const Eigen::Vector2d& p, const std::vector<SceneFloor>& floors) {
  for (const SceneFloor& f : floors) {
    const Eigen::Vector2d d = p - f.centre_xy;
    if (std::abs(d.dot(f.axis_xy[0])) <= f.half_size_m[0] + 1e-9 &&
        std::abs(d.dot(f.axis_xy[1])) <= f.half_size_m[1] + 1e-9)
      return true;
  }
  return false;
}

// The wall's ends (an infinite wall: far away).
void WallEnds(const SceneWall& w, Eigen::Vector2d* a, Eigen::Vector2d* b) {
  const double half = std::isfinite(w.half_length_m) ? w.half_length_m : 1e6;
  *a = w.centre_xy - half * w.along_xy;
  *b = w.centre_xy + half * w.along_xy;
}

}  // namespace

std::string PathProblem(const Scenario& s, const std::vector<SceneWall>& walls,
                        const std::vector<SceneFloor>& floors, int* waypoint, std::string* field) {
  if (field) field->clear();
  const std::string scene = fs::path(s.scene_path).filename().string();
  const double top_z = std::max(s.camera.height_m, 0.3);  // the robot: floor to camera
  std::vector<SceneWall> near;                            // the walls that span the robot's height
  for (const SceneWall& w : walls)
    if (w.z_max_m >= 0.0 && w.z_min_m <= top_z) near.push_back(w);
  const std::vector<WaypointGoal> goals = ResolveWaypoints(s.path, s.robot, s.waypoints);
  for (size_t i = 1; i < s.path.size(); ++i) {
    const Eigen::Vector2d p0 = s.path[i - 1], p1 = s.path[i];
    std::ostringstream where;
    where << "the segment from path[" << i - 1 << "] " << Point(p0) << " to path[" << i << "] "
          << Point(p1);
    *waypoint = static_cast<int>(i);
    for (const SceneWall& w : near) {
      Eigen::Vector2d a, b;
      WallEnds(w, &a, &b);
      double t = 0;
      if (SegmentsCross(p0, p1, a, b, &t)) {
        std::ostringstream msg;
        msg << where.str() << " crosses wall '" << w.name << "' of " << scene << " at "
            << Point(p0 + t * (p1 - p0))
            << " (walls are visual only: the camera would render from outside the scene)";
        return msg.str();
      }
      if (const double d = SegmentDistance(p0, p1, a, b); d < kRobotClearanceM) {
        std::ostringstream msg;
        msg << where.str() << " comes within " << d << " m of wall '" << w.name << "' of " << scene
            << "; the robot (its footprint and camera, " << kRobotClearanceM
            << " m about the wheel axle) needs " << kRobotClearanceM
            << " m: the camera would film through the wall";
        return msg.str();
      }
    }
    // The building's extent: the axle over a floor piece, every 5 cm.
    if (!floors.empty()) {
      const int steps = std::max(1, static_cast<int>(std::ceil((p1 - p0).norm() / 0.05)));
      for (int k = 0; k <= steps; ++k) {
        const Eigen::Vector2d p = p0 + (p1 - p0) * (static_cast<double>(k) / steps);
        if (OverFloor(p, floors)) continue;
        std::ostringstream msg;
        msg << where.str() << " leaves the building of " << scene << " at " << Point(p)
            << " (no floor of the scene there: the camera would see nothing)";
        if (k == 0) *waypoint = static_cast<int>(i - 1);
        return msg.str();
      }
    }
    // A circular arc at path[i] (turn arc, radius_m): every 2 cm of it (chords of R (1 - cos)
    // below 0.2 mm at R >= 0.25 m) keeps the clearance, over the floor.
    if (i + 1 < s.path.size() && goals[i].arc && goals[i].radius_m > 0.0) {
      const CornerArc c = ArcAtCorner(p0, p1, s.path[i + 1], goals[i].radius_m);
      const int steps = std::max(1, static_cast<int>(std::ceil(c.length_m() / 0.02)));
      if (field) *field = "radius_m";
      for (int k = 1; k <= steps; ++k) {
        const Eigen::Vector2d q0 = c.PointAt(c.length_m() * (k - 1) / steps);
        const Eigen::Vector2d q1 = c.PointAt(c.length_m() * k / steps);
        std::ostringstream msg;
        for (const SceneWall& w : near) {
          Eigen::Vector2d e0, e1;
          WallEnds(w, &e0, &e1);
          if (const double d = SegmentDistance(q0, q1, e0, e1); d < kRobotClearanceM) {
            msg << "the arc of radius " << goals[i].radius_m << " m at path[" << i << "] "
                << Point(p1) << " comes within " << d << " m of wall '" << w.name << "' of "
                << scene << " at " << Point(q1) << "; the robot needs " << kRobotClearanceM
                << " m (a smaller radius keeps closer to the corner)";
            return msg.str();
          }
        }
        if (!floors.empty() && !OverFloor(q1, floors)) {
          msg << "the arc of radius " << goals[i].radius_m << " m at path[" << i << "] "
              << Point(p1) << " leaves the building of " << scene << " at " << Point(q1);
          return msg.str();
        }
      }
    }
    if (field) field->clear();
    // An arc corner at path[i]: the robot cuts it within lookahead_m of the corner.
    if (i + 1 < s.path.size() && goals[i].arc && goals[i].radius_m == 0.0) {
      const Eigen::Vector2d p2 = s.path[i + 1];
      const double l_in = std::min(s.robot.lookahead_m, (p1 - p0).norm());
      const double l_out = std::min(s.robot.lookahead_m, (p2 - p1).norm());
      const Eigen::Vector2d a = p1 - l_in * (p1 - p0).normalized();
      const Eigen::Vector2d c = p1 + l_out * (p2 - p1).normalized();
      for (const SceneWall& w : near) {
        Eigen::Vector2d e0, e1;
        WallEnds(w, &e0, &e1);
        const double d = std::min({SegmentDistance(a, c, e0, e1), SegmentDistance(a, p1, e0, e1),
                                   SegmentDistance(p1, c, e0, e1)});
        if (d < kRobotClearanceM || InTriangle(e0, a, p1, c) || InTriangle(e1, a, p1, c)) {
          std::ostringstream msg;
          msg << "the arc at path[" << i << "] " << Point(p1) << " (corner_mode arc, lookahead "
              << s.robot.lookahead_m << " m) comes within " << d << " m of wall '" << w.name
              << "' of " << scene << "; the robot needs " << kRobotClearanceM << " m";
          return msg.str();
        }
      }
    }
  }
  return "";
}

}  // namespace sim
