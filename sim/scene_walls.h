// The walls of a scene as the path check sees them, so that a path through a wall is refused
// before simulating (the walls are visual only: the robot would drive through and the camera
// render from outside the scene).
//
// A wall is a plane geom fixed to the world whose normal is horizontal and one of whose in-plane
// axes is horizontal (the hallway walls of scenes/*.xml). Other geoms (boxes, meshes, tilted
// planes) are not walls here. A floor is a finite plane geom fixed to the world facing up (the
// visible floor pieces; an infinite physics plane is not one): the building's extent.
//
// The path check (PathProblem) keeps the robot inside free space along the whole path: the
// robot, camera included, is a disc of kRobotClearanceM about its wheel axle (the Pioneer 2DX
// chassis' farthest corner is 0.32 m from the axle, and it turns in place about the axle), kept
// that far from every wall along each segment of the polyline and, in corner_mode "arc", along
// the corner it cuts (the triangle of the corner and the points lookahead_m before and after
// it), or along its circular arc (a waypoint's radius_m); and the axle stays over the building's
// floor (a path that leaves the building renders black frames).
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

// A floor piece: a rectangle in the world's xy plane.
struct SceneFloor {
  Eigen::Vector2d centre_xy;           // centre (m)
  Eigen::Vector2d axis_xy[2];          // unit horizontal axes of the plane
  double half_size_m[2] = {0.0, 0.0};  // half extents along the axes (m)
};

// The robot's clearance from a wall (m): the footprint's radius about the axle, camera included.
constexpr double kRobotClearanceM = 0.33;

// The first place where the path leaves free space (see above): "" when none, else the problem,
// and *waypoint = i for the segment path[i-1] -> path[i] (or the corner at path[i]); *field, when
// given, "radius_m" where the circular arc of path[i] is the problem, else "". The walls that
// count span the robot's height (floor to the camera, at least 0.3 m); without floors the
// building's extent is not checked. A waypoint's own turn (Scenario::waypoints) decides its
// corner: in place (the legs only), cut (the triangle above), or a circular arc of radius_m
// (sim/path_follower.h ArcAtCorner), checked every 2 cm along the arc besides the legs.
std::string PathProblem(const Scenario& scenario, const std::vector<SceneWall>& walls,
                        const std::vector<SceneFloor>& floors, int* waypoint,
                        std::string* field = nullptr);

// The walls (and floors) of a loaded model (Simulator::Create checks the path against its own
// model's).
void WallsOfModel(const mjModel* m, std::vector<SceneWall>* walls,
                  std::vector<SceneFloor>* floors = nullptr);

// The walls of the scene at `scene_path`, an MJCF file or a floor plan (loads it): false with
// *error naming the file when it cannot be loaded.
bool WallsOfScene(const std::string& scene_path, std::vector<SceneWall>* walls, std::string* error,
                  std::vector<SceneFloor>* floors = nullptr);

}  // namespace sim
