// The walls of a scene as the path check sees them, so that a path through a wall is refused
// before simulating (the walls are visual only: the robot would drive through and the camera
// render from outside the scene).
//
// A wall is a plane geom fixed to the world whose normal is horizontal and one of whose in-plane
// axes is horizontal (the hallway walls of scenes/*.xml). Other geoms (boxes, meshes, tilted
// planes) are not walls here. The path is checked as the polyline of its waypoints: corners
// cut in corner_mode "arc" are not checked.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/scenario.h"

struct mjModel_;
typedef struct mjModel_ mjModel;

namespace sim {

struct SceneWall {
  std::string name;           // the geom's name ("" when unnamed)
  Eigen::Vector2d centre_xy;  // centre of the plane in the world (m)
  Eigen::Vector2d along_xy;   // unit horizontal in-plane direction
  double half_length_m = 0;   // half extent along `along_xy` (m); infinity for an infinite plane
  double z_min_m = 0;         // vertical extent in the world (m); +-infinity when infinite
  double z_max_m = 0;
};

// The first path segment that crosses one of `walls` spanning the camera height: returns ""
// when none crosses, else the problem, and *waypoint = i for the segment path[i-1] -> path[i].
std::string PathThroughWallProblem(const Scenario& scenario, const std::vector<SceneWall>& walls,
                                   int* waypoint);

// The walls of a loaded model (Simulator::Create checks the path against its own model's).
void WallsOfModel(const mjModel* m, std::vector<SceneWall>* walls);

// The walls of the MJCF scene at `scene_path` (loads it): false with *error naming the file when
// it cannot be loaded.
bool WallsOfScene(const std::string& scene_path, std::vector<SceneWall>* walls, std::string* error);

}  // namespace sim
