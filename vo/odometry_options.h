// The pipeline's options (OdometryOptions and its tracking part, RobustTrackingOptions), their
// defaults, validation and the platform's resolution (ResolvePlatform): what vo_options.yaml
// holds. The stages (front_end.h, tracker.h, motion_estimation.h, recovery.h,
// initial_orientation.h, the window in sliding_window.h) each read the part they need;
// StereoOdometry (odometry.h) holds the effective options (EffectiveOdometryOptions).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>

#include "vo/back_end.h"
#include "vo/bridge_alignment.h"
#include "vo/bundle_adjustment.h"
#include "vo/camera.h"
#include "vo/direct_alignment.h"
#include "vo/disparity.h"
#include "vo/features.h"
#include "vo/image_motion.h"
#include "vo/matcher.h"
#include "vo/plane_orientation.h"
#include "vo/plane_refinement.h"
#include "vo/prior_motion.h"
#include "vo/ransac.h"

namespace vo {

// Detector defaults for the pipeline: Harris, at most 300 features, bucketed on an 8 × 6 grid
// (at most 10 per cell) so they spread over the image, Harris quality_level 0.001.
DetectorOptions DefaultOdometryDetectorOptions();
// Disparity defaults for the pipeline: block matching with the left-right check, both views
// from one cost volume (kBlockMatchingOneVolume; the same disparities as cv::StereoBM run
// twice, in about half the time).
DisparityOptions DefaultOdometryDisparityOptions();

// Image-shift defaults for the pipeline's coarse-to-fine pass: min_score 0.1 instead of 0.3. A
// wrong shift only costs one matching pass that loses to the other on inliers, while a turn
// past nearby walls (perspective, parallax) scores ZNCC ~0.3 at the right shift; the pose
// bridge of a lost frame asks for more (RobustTrackingOptions::rotation_min_shift_score).
ImageShiftOptions DefaultTrackingImageShiftOptions();

// Robust tracking (beyond the paper's unpredicted matcher; used when matcher.prediction is
// kMotionPrior). See the header comment, "Predicted matching".
struct RobustTrackingOptions {
  bool coarse_to_fine = true;  // when the prior is weak (no reliable motion yet, after a lost
                               // frame) or contradicted (the first pass is not confident),
                               // estimate the dominant image shift coarse-to-fine
                               // (image_motion.h) and match again around it
  ImageShiftOptions image_shift = DefaultTrackingImageShiftOptions();  // the coarse-to-fine
                                                                       // estimate
  bool last_motion_pass = true;     // still not confident after that: when the reference (the
                                    // previous frame) measured its own motion and it predicts
                                    // otherwise than the prior (which blends a weak motion in only
                                    // in part), match again around that motion; the pass with more
                                    // inliers wins
  double prior_radius_scale = 0.5;  // the matcher's position gates around the motion prior's
                                    // prediction are scaled by this, in [0.05, 20]: the
                                    // prediction leaves a few pixels (SVD σ 10 → 5 px), and
                                    // a contradicted prior falls to the coarse-to-fine pass
  double shift_radius_scale = 2.0;  // the matcher's position gates are widened by this around
                                    // a shift estimate (a global shift ignores parallax),
                                    // in [0.05, 20]
  int confident_min_inliers = 30;   // a first pass with fewer RANSAC inliers than this ...
  double confident_inlier_fraction = 0.2;  // ... or than this fraction of the smaller feature
                                           // count of the two frames, in [0, 1], is not
                                           // confident: the coarse-to-fine pass is tried too
                                           // and the one with more inliers is kept
  bool guided_rematch = true;              // after RANSAC, predict every reference feature with the
                               // estimated motion and match again in a tight window; the
                               // second pass is kept when it has at least as many inliers
  double guided_radius_scale = 0.3;  // gate scale of that pass (σ 10 px → 3 px), [0.05, 20]
  bool rotation_from_shift = true;   // a frame without a measured motion (too few features, no
                                     // consensus) takes the prior's motion corrected by the
                                     // image shift from the previous frame (the rotation that
                                     // explains the shift left after the prior, see
                                     // CorrectPriorWithImageShift), when that shift is found;
                                     // the measured rotation then becomes the prior's
  double rotation_min_shift_score = 0.85;  // ... with at least this ZNCC, in [-1, 1]: real
                                           // structure scores 0.9-0.99 between successive
                                           // frames, false peaks on plain, smoothly shaded
                                           // walls ~0.7 (measured on the plain corridor)
  double rotation_min_peak_ratio = 1.05;   // ... and an unambiguous peak: best / second-best
                                           // peak score (ImageShiftResult::second_best_ratio)
                                           // at least this, >= 1
  double rotation_min_residual_px = 3.0;   // ... and only when the shift differs from the one
                                           // the prior predicts by more than this (pixels),
                                           // >= 0: smaller residuals are within what a global
                                           // shift cannot tell from parallax and zoom (forward
                                           // motion past plain walls), so the prior stands
  int reliable_min_inliers = 30;           // a motion with at least this many inliers replaces the
                                           // constant-velocity prior; one with fewer moves it only
                                           // part of the way (slerp), one whose bundle
                                           // adjustment was rejected not at all; >= 3. 30 =
                                           // confident_min_inliers: a motion the matcher trusts is
                                           // one the prior may repeat
  double prior_update_exponent = 2.0;      // ... namely (inliers / reliable_min_inliers) to
                                           // this power of the way, >= 1: a weak motion is
                                           // also more often grossly wrong (12 inliers at the edge
                                           // of a plain wall: 1-4 deg of yaw where the robot drove
                                           // straight), not only noisier, so half the support
                                           // moves the prior a quarter of the way. Measured on
                                           // l_hallway texture seeds 1-10 x strides 1/2/3/5 (40
                                           // runs, defaults): exponent 1 / 1.5 / 2 / 3 gave mean
                                           // end-pose error 0.442 / 0.419 / 0.398 / 0.393 m,
                                           // median 0.182 / 0.157 / 0.141 / 0.143 m; 3 took
                                           // camera.pitch_deg 10 to 1.40 % (2: 0.73 %)
  bool few_point_motion = false;  // off unless platform ground_vehicle (measured, l_hallway texture
                                  // seeds 1-10: stride 1 lost frames 113 -> 38, median end-pose
                                  // error 0.347 -> 0.152 m, but strides 2 and 3 worse on seeds 2,
                                  // 5, 10: median 0.256 -> 0.331 m at stride 2). On: when RANSAC
                                  // finds no consensus (too few features or
                                  // matches, or fewer than min_inliers of them agree: a plain
                                  // wall in front of the camera), the motion is
                                  // estimated from the few matches and the motion prior
                                  // (prior_motion.h: 1-point rotation hypotheses, then a
                                  // Gauss-Newton fit regularised by the prior) instead of losing
                                  // the frame; needs a prior (not on the first tracked frame)
  int few_point_min_features = 3;  // a frame with fewer than min_features features with depth,
                                   // but at least this many, is still matched against the
                                   // reference (few_point_motion), >= 1
  // Off unless platform ground_vehicle (measured below). The camera rides a wheeled ground vehicle:
  // where the images cannot measure the motion, it is a wheeled vehicle's. The few-point motion is
  // a yaw about the world's up and a forward distance of the axle, without sideways slip
  // (prior_motion.h, "Ground vehicle"; few_point.no_sideways_slip, few_point.axle_behind_camera_m);
  // its prior, the constant-velocity bridge of a lost frame, loses roll, pitch and lift; a lost
  // frame's rotation from the image shift is a yaw only (the shift's vertical part is zoom and
  // parallax). Needs the up direction from the first frame's orientation (the floor found);
  // without it, 6-DoF. Measured on l_hallway texture seeds 1-10 x strides 1/2/3/5 (40 runs,
  // results/robustness/, with the lost-frame chain, prior_update_exponent 2 and the vehicle_*
  // options below): with few_point_motion, mean end-pose error 0.375 -> 0.306 m, median 0.136 ->
  // 0.131 m, runs <= 0.29 m 26 -> 30, frames without motion 256 -> 171 against the defaults, max
  // 1.498 -> 2.723 m (texture seed 3, stride 5); with the rig's axle (0.15 m) mean 0.294 m and at
  // stride 1 max 1.129 -> 0.588 m; but camera.pitch_deg 10 goes 0.73 -> 1.13 % (drift on the
  // straight approach that the 6-DoF window BA keeps; 0.33 % with vehicle_planar_ba and the
  // axle), so not the default yet. On its own (few_point_motion off) the mean goes 0.375 ->
  // 0.347 m, pitch 10 0.73 -> 0.47 %.
  bool ground_vehicle = false;
  // With ground_vehicle: a weak tracked motion (fewer than reliable_min_inliers RANSAC inliers)
  // that tilts the camera (rotation about an axis across up, the swing of its twist
  // decomposition) by more than vehicle_max_weak_tilt_deg, or lifts it along up by more than
  // vehicle_max_weak_lift_m, is no wheeled vehicle's motion and is rejected (the frame goes on
  // as one whose RANSAC failed: few-point motion, chain or bridge). On a plain wall a few
  // coplanar points let a pitch trade against a vertical step that shows the same image shift:
  // texture seed 3, stride 2, frame 100: 20 inliers, 9.0° of pitch and 0.19 m down while the
  // robot drove straight. Both > 0. Measured with few_point_motion and the rig's axle (0.15 m)
  // on l_hallway texture seeds 1-10 x strides 1/2/3/5 (40 runs): mean end-pose error 0.320 ->
  // 0.304 m; plain_corridor strides 2/3/5 0.168 / 0.415 / 0.379 -> 0.102 / 0.313 / 0.094 m.
  double vehicle_max_weak_tilt_deg = 2.0;
  double vehicle_max_weak_lift_m = 0.03;
  // With ground_vehicle, a lost frame's rotation from the image shift (rotation_from_shift) is
  // a vehicle's: the yaw whose motion, with the camera's swing about the axle
  // (few_point.axle_behind_camera_m), predicts the shift (VehicleMotionFromImageShift). A peak
  // with at least vehicle_rotation_min_shift_score ([-1, 1]) and a best / second-best ratio of
  // at least vehicle_rotation_min_peak_ratio (>= 1) is used too (a turn past a plain wall
  // scores low over the whole overlap but has one clear peak); a shift whose vertical residual
  // (after the prior) exceeds max(rotation_min_residual_px, vehicle_max_vertical_shift_ratio ·
  // its horizontal residual) (>= 0) is zoom and parallax of forward motion, not a turn (the
  // prior stands).
  double vehicle_rotation_min_shift_score = 0.7;
  double vehicle_rotation_min_peak_ratio = 3.0;
  double vehicle_max_vertical_shift_ratio = 0.25;
  // With ground_vehicle (the up known, matcher.prediction motion_prior, no caller's prior), the
  // bridged motion of a lost frame (the prior, its rotation corrected by the image shift) is
  // measured against the previous frame's features without matching them (bridge_alignment.h):
  // the forward step from their depth change, then the yaw that lays the previous features onto
  // this frame's; each where at least vehicle_bridge.min_pairs features pair up. The result
  // becomes the constant velocity (the braking and the turn go on through the next lost frames).
  // The constant velocity otherwise keeps the cruise speed into a robot that stops and turns in
  // front of a plain end wall (texture seed 3, stride 1: 4.2 cm a frame where it moved 0.6 cm)
  // and reads the image shift of off-centre texture as too much yaw (2.8 deg a frame for 2.2).
  // Measured on l_hallway texture seeds 1-10 x strides 1/2/3/5 (40 runs) with few_point_motion,
  // vehicle_planar_ba and the rig's axle (0.15 m): mean end-pose error 0.270 -> 0.219 m, runs
  // <= 0.29 m 31 -> 35, stride 1 max 0.507 -> 0.267 m (every seed under the paper's 0.29 m);
  // without vehicle_planar_ba mean 0.294 -> 0.249 m; ground_vehicle and the axle alone 0.334 ->
  // 0.253 m. It needs the rig's axle: with axle_behind_camera_m 0 on that rig (0.15 m off) the
  // swing is misread and runs <= 0.29 m go 30 -> 26; and without vehicle_planar_ba the pitched
  // camera goes 0.85 -> 1.30 % (ground_vehicle and the axle). Not for the 6-DoF default: without
  // the axle's swing in the model a near wall's sideways flow reads as yaw (mean 0.375 -> 0.405 m).
  bool vehicle_bridge_alignment = true;
  BridgeAlignmentOptions vehicle_bridge;
  // With vehicle_bridge_alignment, a lost (or re-initialised) frame's bridged motion is then
  // measured by aligning the previous left image with this one directly (direct_alignment.h):
  // the previous image's pixels with a gradient on the planes of the features (fitted in each
  // frame with enough of them, carried by the measured or bridged motion through at most 30
  // frames without), the vehicle's yaw and forward step by robust
  // Gauss-Newton on the grey levels, coarse to fine. When it converges with enough pixels and a
  // small enough covariance (vehicle_direct), the frame's motion counts as measured
  // (motion_measured, direct_motion; it is not a lost frame) and becomes the constant velocity.
  // A turn in front of a plain wall whose features are too few for any matcher (texture seed 3,
  // stride 1: 1-14 a frame for 21 frames) is measured from its edges, shadows and specks.
  bool vehicle_direct_alignment = true;
  DirectAlignmentOptions vehicle_direct;
  // The vehicle's planar bundle adjustment and flat floor: the back end's (back_end.h,
  // BackEndOptions::vehicle_planar and flat_floor).
  // A lost frame with at least min_features features is matched against the previous lost
  // frame that had them (the chain), when matching against the reference failed: a turn in
  // front of a plain wall takes the camera past the reference's view, and the frames of the
  // gap, which do overlap each other, then measure the motion through it (rotation and
  // translation, RANSAC with at least min_inliers inliers) instead of extrapolating the prior.
  // The frame stays lost (no link to the window; it counts in lost_frames), its pose is the
  // chain's pose times that motion, and the motion moves the constant-velocity prior as a
  // tracked one does. Not with matcher.prediction none (the paper's form), the Kalman matcher
  // (stateful), or a caller's MotionPrior (it bridges a lost frame as given). Measured on l_hallway
  // texture seeds 1-10 x strides 1/2/3/5 (40 runs, results/robustness/, linear prior update):
  // defaults' median end-pose error 0.206 -> 0.182 m, max 1.958 -> 1.663 m, mean 0.431 -> 0.442 m;
  // plain_corridor better at every stride (0.268-0.569 -> 0.222-0.492 m); with few_point_motion and
  // ground_vehicle mean 0.393 -> 0.328 m.
  bool chain_lost_frames = true;
  PriorMotionOptions few_point;  // that solver (fewer inliers than its min_inliers and
                                 // min_inlier_fraction: lost)
  double few_point_max_shift_disagreement_px =
      3.0;                              // a few-point motion is rejected when
                                        // the image shift it predicts (the image centre at the
                                        // reference's median depth) is farther from the
                                        // coarse-to-fine shift measured for the frame than the
                                        // prior's prediction is, by more than this (pixels), >= 0:
                                        // two wrong matches that agree must not turn the camera by
                                        // degrees that the image does not show, while the global
                                        // shift's own error (parallax and zoom of forward motion)
                                        // is what the prior shows too. No check without a shift.
                                        // A few-point frame is never bundle-adjusted: a BA over a
                                        // few points has no prior and is weaker than the solver
  double few_point_prior_update = 1.0;  // weight of a few-point motion in the constant-velocity
                                        // prior, in [0, 1] (the solver's estimate already
                                        // contains the prior)

  bool IsValid(std::string* error) const;
};

// Where the pipeline evaluates the disparity.
enum class DisparityMode {
  kDense,       // the whole map of every frame (any disparity.algorithm; the speckle filter)
  kAtFeatures,  // only the pixels the features' depth sampling reads, and the right-view
                // pixels of their left-right check (DisparityEstimator::PrepareAtPixels):
                // the same values as the dense map there without its speckle filter, bit for
                // bit; needs disparity.algorithm block_matching_one_volume. The first frame's
                // plane-based orientation still reads a dense map (that one frame)
};
// "dense", "at_features".
const char* ToString(DisparityMode mode);

// What the camera is mounted on (OdometryOptions::platform).
enum class Platform {
  kAuto,           // the caller's rig decides (ResolvePlatform): a rig known to be a ground
                   // vehicle (a wheeled robot on a floor, its axle known) is kGroundVehicle,
                   // anything else kFree. StereoOdometry alone knows no rig: kFree
  kFree,           // 6-DoF: the options as given (the paper's form; a drone, a hand-held rig)
  kGroundVehicle,  // a wheeled robot on one flat floor: the ground-vehicle options on
                   // (tracking.few_point_motion, ground_vehicle, back_end.vehicle_planar,
                   // back_end.flat_floor; the axle from the rig when the options leave it at 0)
};
// "auto", "free", "ground_vehicle".
const char* ToString(Platform platform);

struct OdometryOptions {
  Platform platform = Platform::kAuto;  // see Platform and ResolvePlatform. Measured on the
                                        // simulated differential-drive robot (l_hallway texture
                                        // seeds 1-10 x strides 1/2/3/5, 40 runs): the ground
                                        // vehicle's median / mean end-pose error 0.097 / 0.211 m
                                        // against free's 0.136 / 0.375 m, stride 1 lost frames 31
                                        // against 113 (results/robustness/summary.md)
  DetectorOptions detector = DefaultOdometryDetectorOptions();  // feature detection (left)
  DisparityOptions disparity =
      DefaultOdometryDisparityOptions();  // the block matcher and its post-filters;
                                          // num_disparities is replaced by the value
                                          // derived from the camera when derive_num_disparities
  DisparityMode disparity_mode = DisparityMode::kAtFeatures;  // see DisparityMode
  bool disparity_range_from_scene = true;  // search range per frame from the depths seen:
                                           // the previous frame's largest feature disparity
                                           // · (1 + disparity_range_margin) +
                                           // disparity_range_margin_px, rounded up to 16 and
                                           // at most the camera-derived range; the full range
                                           // on the first frame and after a lost frame
  double disparity_range_margin = 0.25;    // relative margin of that range, >= 0
  double disparity_range_margin_px = 8.0;  // absolute margin (pixels), >= 0
  bool derive_num_disparities = true;      // search range from the camera: the smallest multiple
                                       // of 16 >= fx · baseline / disparity_min_depth_m, clamped
                                       // to [16, max_num_disparities] (and < image width)
  double disparity_min_depth_m = 0.7;  // nearest depth the derived search range covers (metres),
                                       // > 0. Hallway rig (fx 230 px, 0.09 m): 29.6 px → 32
                                       // disparities, depth >= 0.67 m (the L-path's nearest
                                       // surface, at the corner turn, is 0.735 m from the camera
                                       // in the simulator's depth); KITTI (718 px, 0.54 m):
                                       // clamped to 256 (≈ 1.5 m)
  int max_num_disparities = 256;       // upper clamp of the derived range (pixels), multiple
                                       // of 16, >= 16
  DepthSamplingOptions depth;          // how features read the disparity map
  MatcherOptions matcher;              // inter-frame matcher (default: SVD · NCC · Gabor)
  RansacOptions ransac;                // robust frame-to-frame motion
  bool ransac_refine_with_ba = false;  // keep RANSAC's nonlinear refinement
                                       // (ransac.refine_nonlinear) when the BA runs after it;
                                       // false = skip it then (the BA refines anyway; saves
                                       // ~3 ms at 300 features). Without BA it always runs
                                       // as ransac.refine_nonlinear says
  bool estimate_initial_orientation = true;  // hallway frame from the first frame's planes
                                             // (floor/walls); false = world is the first camera
  PlaneOrientationOptions orientation;       // plane extraction for the initial orientation
  int orientation_sample_step_px = 4;  // the first frame's dense disparity map is sampled every
                                       // this many pixels (both axes) for the plane extraction
                                       // (pixels), >= 1. ProcessFeatures uses the features' 3D
  // The first frame's floor (when the plane extraction found one) refined on the images
  // themselves (plane_refinement.h) over the dense map's pixels on the geometric fit: the up and
  // the camera's height then come from it (the yaw stays the walls'). The block matcher's map
  // at a grazing floor is biased: the fit's pitch was off by +0.2..+0.8° on l_hallway texture
  // seeds 1-10 and +1.5° on plain_corridor. Needs the dense map (the first frame of Process;
  // ProcessFeatures has none and skips it).
  bool orientation_floor_refinement = true;
  PlaneRefinementOptions floor_refinement;
  bool orientation_requires_wall = false;  // true: kNoWall (up known, yaw not) also counts as a
                                           // failure (world = first camera); false: the yaw is
                                           // then the camera's heading (zero)
  // When the first frame's planes give no up (neither floor nor ceiling: kNoFloor, e.g. a plain
  // floor without disparity and no ceiling in view), take orientation.expected_up_cam0 as the up
  // — the camera's mounting on a vehicle standing on a level floor — and the camera's heading
  // as the yaw (as with kNoWall), instead of the first camera as the world, which leaves a
  // ground vehicle without its up (no planar motion, no planar BA prior). Off by default; on for
  // a ground vehicle whose rig's pitch is known (ResolvePlatform, which then also sets
  // expected_up_cam0 from that pitch). Measured on plain_corridor texture seeds 3 and 5 at
  // stride 1 (no floor or ceiling found in the first frame): end rotation error 5.1 / 13.9° ->
  // 2.2 / 2.7°, end-pose error 6.9 / 7.0 % -> 4.4 / 5.6 %.
  bool orientation_up_from_mounting = false;
  int adaptive_min_features = 0;  // a Harris detection with fewer features than this is
                                  // repeated with quality_level adaptive_quality_level and the
                                  // larger set kept (weakly textured views: one bright light
                                  // otherwise sets the bar for the whole image), >= 0; 0 = off.
                                  // Off by default: 100 took the L-hallway's texture seeds 1-10
                                  // from a 0.44 to a 0.28 m median end-pose error (114 to 73
                                  // frames without motion), but seed 7 from 0.44 to 0.61 % and
                                  // the plain corridor from 0.26 to 0.69 m (noise-level corners)
  double adaptive_quality_level = 1e-4;  // that second, lower relative threshold, in [0, 1)
  int min_features = 15;  // fewer features with depth than this → lost (black, textureless or
                          // overexposed frame), >= 3
  int min_inliers = 12;   // fewer RANSAC inliers than this → lost, >= 3 (RANSAC's own
                          // min_inliers is raised to this when lower)
  int reinit_after_lost_frames = 10;  // while this many consecutive frames (or more) have been
                                      // lost, a frame whose motion fails against the reference
                                      // re-initialises the pipeline on itself, >= 1. Before
                                      // that, each new frame is matched against the last good
                                      // frame (wide, coarse-to-fine search), so the motion
                                      // across the gap is measured, not extrapolated
  RobustTrackingOptions tracking;     // predicted matching, coarse-to-fine search, guided pass
  BackEndOptions back_end;            // the window, its bundle adjustment, the blend (back_end.h)

  bool IsValid(std::string* error) const;
};

// The options a run on a rig uses: `platform` resolved (never kAuto in the result). kAuto is
// kGroundVehicle when rig_axle_behind_camera_m >= 0 (the caller knows the rig is a ground
// vehicle and where its wheel axle is: a simulated robot, a dataset with the rig's
// description), kFree otherwise. kGroundVehicle switches tracking.few_point_motion,
// ground_vehicle, back_end.vehicle_planar and back_end.flat_floor on (so on that platform they
// cannot be switched off one by one: use kFree and set them). With ground_vehicle on (either way),
// tracking.few_point.axle_behind_camera_m left at 0 takes the rig's axle when it is known.
// On kGroundVehicle with the rig's camera pitch known (rig_pitch_deg finite: the optical axis's
// downward tilt, degrees), orientation_up_from_mounting is switched on and
// orientation.expected_up_cam0, when left at its default (−y: an upright, level camera), becomes
// the up that pitch gives, (0, −cos p, −sin p).
OdometryOptions ResolvePlatform(const OdometryOptions& options, double rig_axle_behind_camera_m,
                                double rig_pitch_deg = std::numeric_limits<double>::quiet_NaN());

// The options as the pipeline uses them: the platform resolved without a rig (ResolvePlatform
// with no axle known), the disparity search range derived from the camera
// (derive_num_disparities), RANSAC's min_inliers raised to min_inliers, and RANSAC's nonlinear
// refinement off when the bundle adjustment follows (ransac_refine_with_ba false).
OdometryOptions EffectiveOdometryOptions(const StereoCamera& camera,
                                         const OdometryOptions& options);

}  // namespace vo
