#include "sim/scene_walls.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

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

void WallsOfModel(const mjModel* m, std::vector<SceneWall>* walls) {
  mjData* d = mj_makeData(m);
  mj_kinematics(m, d);  // geom_xpos, geom_xmat
  walls->clear();
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_type[g] != mjGEOM_PLANE || m->body_weldid[m->geom_bodyid[g]] != 0) continue;
    const mjtNum* R = d->geom_xmat + 9 * g;  // row-major; columns are the geom's axes
    const Eigen::Vector3d x(R[0], R[3], R[6]), y(R[1], R[4], R[7]), normal(R[2], R[5], R[8]);
    if (std::abs(normal.z()) > kAxisTolerance) continue;  // floor, ceiling, a tilted plane
    const mjtNum* size = m->geom_size + 3 * g;
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

bool WallsOfScene(const std::string& scene_path, std::vector<SceneWall>* walls,
                  std::string* error) {
  char load_error[1024] = "";
  mjModel* m = mj_loadXML(scene_path.c_str(), nullptr, load_error, sizeof(load_error));
  if (!m) {
    *error = scene_path + ": cannot load MJCF scene: " + load_error;
    return false;
  }
  WallsOfModel(m, walls);
  mj_deleteModel(m);
  return true;
}

std::string PathThroughWallProblem(const Scenario& s, const std::vector<SceneWall>& walls,
                                   int* waypoint) {
  const double camera_z = s.camera.height_m;
  for (size_t i = 1; i < s.path.size(); ++i) {
    const Eigen::Vector2d p = s.path[i - 1], r = s.path[i] - s.path[i - 1];
    for (const SceneWall& w : walls) {
      if (!(camera_z >= w.z_min_m && camera_z <= w.z_max_m)) continue;
      // p + t r = centre + u along, t in [0, 1], |u| <= half length.
      const double denom = Cross(r, w.along_xy);
      if (std::abs(denom) < 1e-12) continue;  // parallel to the wall
      const Eigen::Vector2d q = w.centre_xy - p;
      const double t = Cross(q, w.along_xy) / denom;
      const double u = Cross(q, r) / denom;
      if (t < 0 || t > 1 || std::abs(u) > w.half_length_m) continue;
      *waypoint = static_cast<int>(i);
      std::ostringstream msg;
      msg << "the segment from path[" << i - 1 << "] " << Point(s.path[i - 1]) << " to path[" << i
          << "] " << Point(s.path[i]) << " crosses wall '" << w.name << "' of "
          << fs::path(s.scene_path).filename().string() << " at " << Point(p + t * r)
          << " (walls are visual only: the camera would render from outside the scene)";
      return msg.str();
    }
  }
  return "";
}

}  // namespace sim
