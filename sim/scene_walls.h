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

namespace sim {

struct SceneWall {
  std::string name;           // the geom's name ("" when unnamed)
  Eigen::Vector2d centre_xy;  // centre of the plane in the world (m)
  Eigen::Vector2d along_xy;   // unit horizontal in-plane direction
  double half_length_m = 0;   // half extent along `along_xy` (m); infinity for an infinite plane
  double z_min_m = 0;         // vertical extent in the world (m); +-infinity when infinite
  double z_max_m = 0;
};

// The walls of the MJCF scene at `scene_path` (cached by path, size and modification time).
// False (with *error) when the scene does not load.
bool ReadSceneWalls(const std::string& scene_path, std::vector<SceneWall>* walls,
                    std::string* error);

// The first path segment that crosses a wall spanning the camera height: returns "" when none
// crosses (or the scene does not load: the simulator reports that), else the problem, and
// *waypoint = i for the segment path[i-1] -> path[i].
std::string PathThroughWallProblem(const Scenario& scenario, int* waypoint);

}  // namespace sim
