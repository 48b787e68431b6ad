// The back end of the pipeline (Kwolek, docs/PAPER.md "refinement", section V): the feature tracks
// of the last few frames, those frames' poses, and the windowed bundle adjustment with its
// divergence guard. StereoOdometry (odometry.h) keeps the front end, RANSAC, the blend with
// the motion prior and the tracking status; this class owns what the window remembers.
//
//   Start(frame, features, T)         a new window: tracks begin on this frame's features
//   Add(frame, features, inliers, T)  tracks continued by the inlier matches, the frame's
//                                     initial pose stored; poses outside the window dropped
//   Refine(camera, frame)             bundle adjustment over the window (oldest pose fixed);
//                                     the refined poses replace the stored ones unless the
//                                     newest moved farther than the guard allows
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "vo/bundle_adjustment.h"
#include "vo/camera.h"
#include "vo/tracks.h"
#include "vo/types.h"

namespace vo {

struct SlidingWindowOptions {
  int window_frames = 5;              // frames kept (tracks and poses), >= 1
  bool use_bundle_adjustment = true;  // false: Refine() does nothing
  int max_points = 100;               // at most this many BA points, those seen in the most
                                      // frames (ties: the older tracks); 0 = all
  double max_correction_m = 0.25;     // divergence guard: a BA that moves the newest pose
  double max_correction_deg = 5.0;    // farther (metres / degrees) is rejected
  BundleAdjustmentOptions ba;         // the solver (ba.min_frames_per_point selects points)
};

// A relative-rotation prior between two frames of the window (frame indices): the rotation
// R_a_b of camera frame_b in camera frame_a (a gyro's), σ sigma_rad (BundleAdjustmentProblem::
// rotation_priors).
struct WindowRotationPrior {
  int64_t frame_a = -1;
  int64_t frame_b = -1;
  Eigen::Matrix3d R_a_b = Eigen::Matrix3d::Identity();
  double sigma_rad = 1.0;  // radians, > 0
};

// What Refine() did.
struct WindowRefinement {
  bool attempted = false;  // the window had at least two poses and more than the fixed ones
  bool ran = false;        // the BA result was used (the stored poses are refined)
  bool rejected = false;   // the divergence guard rejected it (`message` says by how much)
  std::string message;
  int num_frames = 0;                // poses in the problem (when ran)
  int num_points = 0;                // points optimised (when ran)
  double rms_reprojection_px = 0.0;  // inlier rms after the BA (when ran)
};

class SlidingWindow {
 public:
  explicit SlidingWindow(const SlidingWindowOptions& options);

  void Reset();
  // A new window on `frame_index` at pose T_world_cam0 (tracks start on its features).
  TrackUpdateResult Start(int64_t frame_index, std::vector<Feature>* features,
                          const Eigen::Isometry3d& T_world_cam0);
  // Continues the tracks by `inlier_matches` (reference index → features index), stores the
  // frame's initial pose and keeps the poses of the window's frames only. On failure nothing
  // changes but the tracks' own state (see TrackManager::AddFrame).
  TrackUpdateResult Add(int64_t frame_index, std::vector<Feature>* features,
                        const std::vector<Match>& inlier_matches,
                        const Eigen::Isometry3d& T_world_cam0_initial);
  // Bundle adjustment of the window, `newest_frame_index` the frame just added.
  // `planar`: a ground vehicle's motion prior between consecutive window poses (off unless
  // enabled; BundleAdjustmentProblem::planar). `rotations`: relative-rotation priors between
  // frames of the window (those of a frame not in the problem are left out).
  WindowRefinement Refine(const StereoCamera& camera, int64_t newest_frame_index,
                          const PlanarMotionPrior& planar = PlanarMotionPrior(),
                          const std::vector<WindowRotationPrior>& rotations = {});

  // Pose of a frame of the window (null when it is not in the window).
  const Eigen::Isometry3d* Pose(int64_t frame_index) const;
  const TrackManager& tracks() const { return tracks_; }
  const SlidingWindowOptions& options() const { return options_; }

 private:
  SlidingWindowOptions options_;
  TrackManager tracks_;
  std::map<int64_t, Eigen::Isometry3d> T_world_cam0_by_frame_;  // window poses (frame index)
};

// Keeps at most max_points points of a window problem (0 = all): those seen in the most frames
// (at least min_frames), ties by index (= ascending track id, the older tracks first). Points
// left out are dropped with their observations; the others are re-indexed.
BundleAdjustmentProblem SelectBaPoints(BundleAdjustmentProblem problem, int max_points,
                                       int min_frames);

}  // namespace vo
