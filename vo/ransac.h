// Robust frame-to-frame motion of a stereo head: RANSAC (Fischler & Bolles 1981) around the
// closed-form quaternion estimator of horn.h. Kwolek, docs/PAPER.md "outliers": RANSAC seeded with
// features tracked stably over the last frames; iteration count from the desired confidence
// (Stewart 1999, "Robust parameter estimation in computer vision", SIAM Review 41(3)).
//
// Model and conventions. Each correspondence holds a 3D point p_prev in the previous frame's
// cam0 (metres, from the previous disparity) and its observation in the current stereo pair:
// left pixel uv and disparity d, so the right pixel is (u − d, v) (rectified pair, camera.h).
// The model fitted is T_curr_prev (p_curr = T_curr_prev * p_prev); the result reports the
// camera motion T_prev_curr = T_curr_prev⁻¹ (p_prev = T_prev_curr * p_curr), the house's
// frame-to-frame convention.
//
// Per iteration: draw 3 distinct correspondences, fit T_curr_prev with Horn's method from
// p_prev (source) to the current 3D points p_curr = Backproject(uv, d) (target), and score it
// by REPROJECTION error in BOTH current images: a correspondence is an inlier when
// T_curr_prev * p_prev lies in front of the camera and projects within inlier_threshold_px of
// the observation in the left image AND in the right image. Image errors are used, not 3D
// distances, because stereo depth error grows with the square of the distance while the
// image error does not. Score = inlier count, ties broken by the smaller sum of squared
// errors over the inliers.
//
// Seeding with stable tracks: correspondences are ranked by track_age (descending, ties by
// index); the "stable pool" is the top ceil(stable_pool_fraction * n) of them (at least
// min_stable_pool_size), extended to include every correspondence whose age equals the last
// one's (so the pool never splits a group of equal age). The first num_seeded_iterations
// iterations draw their three points from the stable pool only; later iterations draw from
// all correspondences. When the pool would hold every correspondence (e.g. all ages equal) no
// iteration is seeded. Rationale: long tracks survived several matching rounds, so they are
// more likely inliers, and an early good model shrinks the adaptive iteration count.
//
// Iteration count (Hartley & Zisserman eq. 4.18, Stewart 1999): after each improvement,
// N = ceil(log(1 − confidence) / log(1 − w³)) with w = best inlier count / n; the loop stops
// after max(min_iterations, N) iterations, never more than max_iterations. Degenerate samples
// (collinear / coincident points) count as iterations.
//
// Local optimisation (LO-RANSAC, Chum, Matas & Kittler 2003): each time a sample gives a new
// best model, T_curr_prev is fitted to the current left+right reprojections of that model's
// inliers (p_prev fixed; ceres::TinySolver, autodiff, a few Levenberg-Marquardt steps),
// re-classified, and kept while the score improves (local_optimization_iterations rounds).
// A minimal sample of three noisy stereo points is a poor model (depth noise ∝ z², and a
// 3D-3D fit weights it isotropically), so without LO the best sample model supports only
// part of the inliers and the adaptive count, fed that low ratio, runs long or stops on it.
//
// Refits weight each pair by 1 / (z_prev⁴ + z_curr⁴) (inverse stereo depth variance) unless
// refit_depth_weighted is false; Horn's plain least squares lets the far points dominate.
//
// Final estimate: Horn refit on all inliers, re-classify, repeat (refit_iterations times or
// until the inlier set stops changing; a refit that loses inliers is dropped); then, optionally, a
// small nonlinear least-squares refinement of T_curr_prev (Ceres, unit quaternion on
// EigenQuaternionManifold + translation) minimising the left+right reprojection errors of the
// inliers, eq. (8), followed by a last re-classification. Where a correspondence carries its
// previous observation, the refinement is a two-frame bundle adjustment: the point is a free
// parameter observed in the previous pair (left + right) and, through T_curr_prev, in the current
// pair (Schur elimination of the points). Otherwise p_prev is held fixed, and its depth error
// (which grows as z² / (f b)) then enters the current right-image residual unweighted. Measured on
// synthetic data (tests/vo/ransac_test.cc, 0.5 px noise, depths 1.5–6 m, 180 inliers, 25 cm
// motion): mean translation error 1.9 mm two-frame, 3.0 mm fixed points, 5.8 mm without the final
// refinement, 81 mm with plain (unweighted, no LO) Horn refits alone: 3D errors weighted
// equally let the noisy depth of far points dominate, the bias the paper warns of.
//
// The inlier test always uses the fixed p_prev, so inlier_threshold_px must cover the
// current pixel noise plus the previous depth error seen in the right image (≈ the previous
// disparity noise): about 3σ of the combined per-image error.
//
// Determinism: all randomness comes from a SplitMix64 generator seeded by options.seed (no
// std:: distributions); the same input and seed give the same result bit for bit.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/horn.h"
#include "vo/types.h"

namespace vo {

// SplitMix64 (Steele, Lea & Flood 2014): small, seeded, platform-independent generator.
// Used for RANSAC sampling here and in plane_orientation.cc.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform integer in [0, n), n >= 1, without modulo bias (rejection of the top remainder).
  uint64_t UniformIndex(uint64_t n) {
    const uint64_t limit = ~uint64_t{0} - (~uint64_t{0} % n);  // multiple of n
    uint64_t x = Next();
    while (x >= limit) x = Next();
    return x % n;
  }
  // Uniform double in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }

 private:
  uint64_t state_;
};

// One putative match between a previous-frame 3D point and a current stereo observation.
struct StereoCorrespondence {
  Eigen::Vector3d p_prev_cam0 = Eigen::Vector3d::Zero();  // point in the previous frame's cam0
                                                          // (metres), z > 0
  Eigen::Vector2d uv_curr_px = Eigen::Vector2d::Zero();   // observation in the current left
                                                          // image (pixels)
  double disparity_curr_px = 0.0;  // current disparity x_left − x_right (pixels), > 0; the
                                   // right-image observation is (u − d, v)
  int track_age = 0;  // number of earlier frames the track was seen in (>= 0); larger = more
                      // stable, used for seeding
  // Optional: the previous observation p_prev was triangulated from. When given
  // (disparity_prev_px > 0), the nonlinear refinement treats the point as unknown and fits
  // it to both frames (a two-frame bundle adjustment), instead of holding p_prev fixed.
  Eigen::Vector2d uv_prev_px = Eigen::Vector2d::Zero();  // previous left image (pixels)
  double disparity_prev_px = -1.0;  // previous disparity (pixels); <= 0 = not given

  bool has_prev_observation() const { return disparity_prev_px > 0.0; }
};

// Correspondences for the matches whose both features have depth: p_prev from prev[m.prev]
// (with its uv and disparity as the previous observation), the current observation from
// curr[m.curr], track_age = prev[m.prev].track_age. match_index
// (optional) receives, per correspondence, the index of its match in `matches`. Matches with
// out-of-range indices are skipped.
std::vector<StereoCorrespondence> MakeStereoCorrespondences(
    const std::vector<Feature>& prev, const std::vector<Feature>& curr,
    const std::vector<Match>& matches, std::vector<int>* match_index = nullptr);

struct RansacOptions {
  double inlier_threshold_px = 2.0;   // max reprojection error (pixels, Euclidean) in EACH of
                                      // the current left and right images for an inlier, > 0
                                      // (see the header comment on what it must cover)
  double confidence = 0.999;          // probability that at least one all-inlier sample is drawn,
                                      // drives the adaptive iteration count, in (0, 1)
  int min_iterations = 20;            // never stop before this many iterations, >= 1
  int max_iterations = 500;           // never run more than this many iterations, >= min_iterations
  int min_inliers = 6;                // fewer inliers than this (and fewer than 3 matches) means no
                                      // consensus (kNoConsensus / kTooFewMatches), >= 3
  int num_seeded_iterations = 20;     // the first iterations sample only the stable pool (see
                                      // header comment), >= 0; 0 disables seeding
  double stable_pool_fraction = 0.3;  // stable pool = this share of the correspondences with
                                      // the oldest tracks, in (0, 1]
  int min_stable_pool_size = 8;       // the stable pool holds at least this many (>= 3)
  uint64_t seed = 0x5eed;             // seed of the sample generator
  double sample_collinear_tolerance = 1e-3;  // minimal samples whose 3D points (either frame)
                                             // have σ₂/σ₁ below this are skipped as
                                             // degenerate (dimensionless), in [0, 1)
  int refit_iterations = 3;                  // Horn refits on the inlier set, each followed by
                             // re-classification; stops early when the set is stable, >= 0
  bool refit_depth_weighted = true;  // weight the refits' pairs by 1 / (z_prev⁴ + z_curr⁴),
                                     // the inverse of the stereo depth variance (∝ z⁴);
                                     // false = Horn's plain, equally weighted least squares
  int local_optimization_iterations = 3;  // LO-RANSAC: rounds of reprojection fit +
                                          // re-classification for each new best model, >= 0;
                                          // 0 disables
  bool refine_nonlinear = true;    // finish with a Ceres reprojection refinement on the inliers
  int refine_max_iterations = 10;  // Levenberg-Marquardt iteration limit of that refinement, >= 1
  bool refine_points = true;       // refine the points of correspondences that carry their previous
                                   // observation (two-frame bundle adjustment); false = hold every
                                   // p_prev fixed
  // Transformed points closer than this (z, metres) are outliers: a numerical guard against a
  // point at or behind the camera, not a setting (it was the key ransac.min_depth_m).
  static constexpr double kMinDepthM = 1e-3;

  bool IsValid(std::string* error) const;
};

struct RansacResult {
  enum class Status {
    kOk,             // T_prev_curr is supported by at least min_inliers inliers
    kTooFewMatches,  // fewer than max(3, min_inliers) correspondences
    kNoConsensus,    // no model reached min_inliers (T_prev_curr = best found, or identity)
    kInvalidInput,   // invalid options or camera, non-finite numbers, disparity <= 0
  };
  Status status = Status::kInvalidInput;
  std::string message;  // empty when kOk
  Eigen::Isometry3d T_prev_curr =
      Eigen::Isometry3d::Identity();  // camera motion:
                                      // p_prev = T_prev_curr * p_curr (cam0 frames)
  std::vector<bool> inlier_mask;      // one per correspondence; true = inlier of T_prev_curr
  int num_inliers = 0;
  int num_iterations = 0;            // RANSAC iterations run (seeded ones included)
  int num_seeded_iterations = 0;     // of those, drawn from the stable pool
  int stable_pool_size = 0;          // size of the stable pool (0 when seeding was off)
  double rms_reprojection_px = 0.0;  // sqrt(mean over inliers and both images of |e|²)
                                     // (pixels) for the final T_prev_curr, with p_prev fixed
                                     // as in the inlier test (includes its depth error)
  bool refined = false;              // true when the nonlinear refinement was run and kept

  bool ok() const { return status == Status::kOk; }
};

// "ok", "too_few_matches", "no_consensus", "invalid_input".
const char* ToString(RansacResult::Status status);

// N = ceil(log(1 − confidence) / log(1 − w^sample_size)); 0 when w >= 1, INT_MAX when w <= 0
// (clamped to INT_MAX). The standard RANSAC iteration bound (Hartley & Zisserman eq. 4.18).
int RansacRequiredIterations(double inlier_ratio, int sample_size, double confidence);

// Reprojection errors (pixels) of p_prev under T_curr_prev in the current left and right
// images; false when the transformed point is not in front of the camera (z <= min_depth_m).
bool StereoReprojectionErrors(const StereoCamera& cam, const Eigen::Isometry3d& T_curr_prev,
                              const StereoCorrespondence& c, double min_depth_m,
                              Eigen::Vector2d* err_left_px, Eigen::Vector2d* err_right_px);

// LO-RANSAC's local optimisation: T_curr_prev (in: the start, out: the fit) fitted to the
// current-frame reprojections (StereoReprojectionErrors) of the fixed previous-frame points of
// corr[indices] by ceres::TinySolver (Levenberg-Marquardt, at most max_iterations, over the
// angle-axis and the translation). The Jacobian is the one ceres::TinySolverAutoDiffFunction
// gives, computed with the rotation's terms once per evaluation (the same fit bit for bit,
// RansacTest.TheLocalFitIsCeresAutoDiffFitBitForBit). False with fewer than 3 points or a
// non-finite result.
bool FitReprojectionFixedPoints(const StereoCamera& cam,
                                const std::vector<StereoCorrespondence>& corr,
                                const std::vector<int>& indices, int max_iterations,
                                Eigen::Isometry3d* T_curr_prev);

// Robust T_prev_curr from putative stereo correspondences (see the header comment). Never throws.
RansacResult EstimateMotionRansac(const StereoCamera& cam,
                                  const std::vector<StereoCorrespondence>& correspondences,
                                  const RansacOptions& options = RansacOptions());

}  // namespace vo
