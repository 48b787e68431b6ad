// Initial orientation of the stereo head from the first frame's 3D points, for a piecewise-
// planar indoor scene. Kwolek, docs/PAPER.md "initial orientation" / section VI: the paper runs
// POSIT (DeMenthon & Davis 1995) on the output of a plane extractor. With stereo depth the
// planes already give the orientation directly, so no POSIT is needed: we extract the
// dominant planes (floor, walls, ceiling) and read the camera's orientation off their normals.
//
// Hallway frame ("hall"): x along the corridor (the corridor direction closest to the
// camera's viewing direction), y to the left, z up (right-handed; the floor is z = 0 when
// the origin is put on it). The result is R_hall_cam0 (p_hall = R_hall_cam0 * p_cam0, up to
// the translation, which is not estimated except for the height).
//
// Steps:
//   1. Sequential RANSAC plane extraction (seeded SplitMix64, 3-point samples; inlier when
//      the point-plane distance is below distance_threshold_m + distance_threshold_per_m * z,
//      since stereo depth error grows with depth; MSAC scoring); each plane is refitted by
//      weighted least squares (smallest eigenvector of the inliers' scatter, weight
//      1 / threshold², so noisy far points count less) and its inliers removed; up to
//      max_planes planes with at least min_plane_inliers inliers each. Then a corner pass
//      refits every plane on its exclusive inliers (within the threshold of this plane and
//      of no other), so the points near an edge shared with a neighbour (the foot of a
//      wall) do not tilt it; num_inliers / rms_distance_m count those exclusive inliers.
//   2. Horizontal planes: normal within max_normal_deviation_deg of the prior up direction
//      expected_up_cam0 (default −y_cam0: camera roughly upright). The floor is the
//      horizontal plane with the most inliers that lies below the camera, the ceiling the one
//      above. up = floor normal (pointing to the camera's side); without a floor, the negated
//      ceiling normal. Neither → kNoFloor.
//   3. Walls: normal within max_normal_deviation_deg of perpendicular to up. Walls of a
//      hallway are parallel or perpendicular (Manhattan world), so the corridor directions
//      are the angle of each wall normal in the horizontal plane modulo 90°; the inlier-
//      weighted circular mean of 4·angle gives the Manhattan frame; of its four horizontal
//      axes, x_hall is the one closest to the camera's forward axis projected on the
//      horizontal plane. Hence the yaw is recovered modulo 90°, i.e. correctly while the
//      camera looks within ±45° of the corridor axis. No wall → kNoWall (up and height are
//      still valid; x_hall is then the camera's forward axis projected, i.e. zero yaw).
//   3b. Manhattan refinement (optional, when there is a wall): each floor/ceiling/wall normal
//      is snapped to its hallway axis (±x, ±y, ±z) under that first estimate, and the
//      rotation is refitted to all of them at once (weighted by inlier count; orthogonal
//      Procrustes solved with horn.h on the point pairs ±axis → ±normal). The walls then
//      also correct the floor normal's error along the wall normals. up_cam0 is updated.
//   4. Camera height above the floor = signed distance of the cam0 origin from the floor
//      plane (metres); 0 when there is no floor.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace vo {

// A plane n·p + d = 0 in cam0 (n unit, metres).
struct Plane {
  enum class Kind { kUnknown, kFloor, kCeiling, kWall };
  Eigen::Vector3d normal_cam0 = Eigen::Vector3d::UnitZ();  // unit normal; for floor/ceiling/
                                                           // wall it points to the camera side
  double offset_m = 0.0;        // d in n·p + d = 0 (metres) = distance of the cam0 origin from the
                                // plane along n (>= 0 once oriented to the camera side)
  int num_inliers = 0;          // exclusive inliers (see step 1)
  double rms_distance_m = 0.0;  // rms point-plane distance of those inliers (metres)
  Kind kind = Kind::kUnknown;
};

const char* ToString(Plane::Kind kind);

struct PlaneOrientationOptions {
  int max_planes = 5;                      // planes extracted at most, >= 1
  int min_plane_inliers = 30;              // a plane needs at least this many inliers, >= 3
  double distance_threshold_m = 0.02;      // inlier distance at zero depth (metres), > 0
  double distance_threshold_per_m = 0.01;  // growth of the inlier distance per metre of depth
                                           // z (metres per metre), >= 0
  int ransac_iterations = 300;             // RANSAC iterations per plane, >= 1
  uint64_t seed = 0x91a7e;                 // seed of the sample generator
  // Prior up direction in cam0 (any length > 0); −y = camera upright.
  Eigen::Vector3d expected_up_cam0 = Eigen::Vector3d(0.0, -1.0, 0.0);
  double max_normal_deviation_deg = 30.0;  // a horizontal plane's normal may deviate this
                                           // much from the prior up, and a wall's from
                                           // perpendicular to the estimated up (degrees),
                                           // in (0, 45]
  bool manhattan_refinement = true;        // refit the rotation to the floor/ceiling AND wall
                                           // normals together (step 3b); false = up from the floor
                                           // (or ceiling) alone, yaw from the walls

  bool IsValid(std::string* error) const;
};

struct PlaneOrientationResult {
  enum class Status {
    kOk,            // floor (or ceiling) and at least one wall found; R_hall_cam0 complete
    kNoFloor,       // no floor and no ceiling: no up direction; R_hall_cam0 = identity
    kNoWall,        // up and height valid, yaw unknown (taken as 0, see header comment)
    kInvalidInput,  // invalid options or non-finite points
  };
  Status status = Status::kInvalidInput;
  std::string message;                                        // empty when kOk
  Eigen::Matrix3d R_hall_cam0 = Eigen::Matrix3d::Identity();  // p_hall = R_hall_cam0 * p_cam0
  Eigen::Vector3d up_cam0 = Eigen::Vector3d::Zero();          // unit up direction in cam0 (z_hall)
  double camera_height_m = 0.0;  // height of cam0's centre above the floor (metres); 0 when
                                 // no floor was found (also when only a ceiling was)
  int floor_index = -1;          // index into planes, or -1
  int ceiling_index = -1;        // index into planes, or -1
  std::vector<Plane> planes;     // every plane extracted, in extraction order (largest first)

  bool ok() const { return status == Status::kOk; }
};

const char* ToString(PlaneOrientationResult::Status status);

// The inlier distance of a point p_cam0 from a plane (metres): distance_threshold_m +
// distance_threshold_per_m · z (header, step 1).
double PlaneInlierDistance(const Eigen::Vector3d& p_cam0, const PlaneOrientationOptions& options);

// The horizontal basis of a camera whose up is `up` (unit, cam0 frame): e1 = the camera's forward
// axis projected on the horizontal plane (its x axis when it looks straight up or down), e2 = up
// × e1 (left). With zero yaw e1 is the hallway's x.
void HorizontalBasis(const Eigen::Vector3d& up, Eigen::Vector3d* e1, Eigen::Vector3d* e2);

// Orientation of cam0 relative to the hallway from 3D points in cam0 (metres), e.g. the first
// frame's features or a subsampled dense disparity map. Never throws.
PlaneOrientationResult EstimateHallwayOrientation(
    const std::vector<Eigen::Vector3d>& points_cam0,
    const PlaneOrientationOptions& options = PlaneOrientationOptions());

}  // namespace vo
