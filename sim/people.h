// People walking through the scene (issue #34; scenario keys people.*, sim/scenario.h
// PeopleOptions): kinematic MuJoCo mocap bodies of human proportions, textured with the
// procedural generator (sim/textures.h), each walking its own path back and forth.
//
// Body (height h, a person's frame: x the walking direction, z up, origin on the floor): two
// legs (boxes 0.09h deep, 0.08h wide, 0.49h long, hips at 0.49h, 0.055h either side of the
// centre) that swing +-25 degrees about the hips, once per 0.8h walked; a torso (box 0.14h deep,
// 0.22h wide, from 0.47h to 0.82h); two arms (capsules of radius 0.028h at +-0.14h, from 0.80h
// down to 0.47h); a neck and a head (a sphere of radius 0.07h at 0.92h). The person's half width
// (arms included) is 0.168h: paths keep kPersonClearance * h from walls.
//
// Paths (PlanPeople), person i drawing from DeriveSeed(people.seed, i, 5):
// - a floor-plan scene with at least two named places: two distinct places drawn, the path
//   between them planned by the plan's planner (PlanPath, sim/floor_plan.h) keeping
//   kPersonClearance * h from every wall and box; a pair without a path is drawn again;
// - otherwise (an MJCF scene): a line parallel to a segment of the robot's path, beside it, that
//   keeps kPersonClearance * h from every wall and kRobotClearanceM + kPersonClearance * h from
//   the robot's whole path (a person never walks into the robot or its camera), over the floor,
//   at least kMinPersonLineM long (at most kMaxPersonLineM): among all such lines (offsets every
//   5 cm, both sides, every segment) one drawn, and its stretch.
// Each person walks its path back and forth at people.speed_mps, starting at a drawn point of
// the round trip (phase), turning on the spot at the ends.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/scenario.h"
#include "sim/scene_walls.h"

struct mjModel_;
typedef struct mjModel_ mjModel;
struct mjData_;
typedef struct mjData_ mjData;

namespace sim {

constexpr double kPersonClearance = 0.17;  // times the height: half width with arms and a margin
constexpr double kMinPersonLineM = 1.5;    // MJCF scenes: the shortest line a person walks (m)
constexpr double kMaxPersonLineM = 6.0;    // MJCF scenes: the longest (m)
constexpr double kLegSwingDeg = 25.0;      // legs' swing either way about the hips
constexpr double kStridePerHeight = 0.8;   // distance walked per leg cycle, times the height

// One person's path: a polyline walked back and forth.
struct PersonPath {
  std::vector<Eigen::Vector2d> points;  // >= 2 (m)
  double length_m = 0.0;                // along the polyline
  double phase_m = 0.0;                 // where on the round trip (0 .. 2 length) at t = 0
};

// Where a person is at time t (s from frame 0).
struct PersonPose {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // on the floor (m)
  double yaw_rad = 0.0;                          // the walking direction
  double walked_m = 0.0;                         // distance walked since the phase origin
};

// The paths of the scenario's people (see above). False with *error (a message for the key
// people.count) when no path can be found. `walls`/`floors` are the scene's (scene_walls.h).
bool PlanPeople(const Scenario& scenario, const std::vector<SceneWall>& walls,
                const std::vector<SceneFloor>& floors, std::vector<PersonPath>* paths,
                std::string* error);

// Position and heading at time t: the round trip of 2 length_m at speed_mps from phase_m.
PersonPose PersonAt(const PersonPath& path, double speed_mps, double t_s);

// The MJCF the people add to a scene: "<asset>...</asset><worldbody>...</worldbody>" (bodies
// person<i>, person<i>_leg_l, person<i>_leg_r, all mocap; geoms without contacts).
std::string PeopleMjcf(const PeopleOptions& options);

// The people of a loaded model: their textures filled, and their bodies moved.
class People {
 public:
  // False with *error when the model lacks the bodies of PeopleMjcf.
  bool Init(mjModel* m, const PeopleOptions& options, std::vector<PersonPath> paths,
            std::string* error);
  // Sets the mocap bodies' poses for time t (before mj_step1 / mj_forward).
  void Apply(const mjModel* m, mjData* d, double t_s) const;
  const std::vector<PersonPath>& paths() const { return paths_; }
  // The mocap index of person i's body.
  int body_mocap(int i) const { return mocap_[3 * i]; }

 private:
  PeopleOptions options_;
  std::vector<PersonPath> paths_;
  std::vector<int> mocap_;  // per person: body, left leg, right leg
};

}  // namespace sim
