// Back-end timings, single thread: Horn's closed form on 100 points, RANSAC on 300 stereo
// matches with 30% outliers, windowed bundle adjustment over 5 frames x 150 tracks (and the
// paper's 3 frames x 16 features, and the pipeline's 5 frames x 100 points with its BA
// settings), with Ceres (SPARSE_SCHUR, DENSE_SCHUR) and the hand-written Schur-complement
// Levenberg-Marquardt (schur_lm.h). Paper (Pentium IV 2.4 GHz): SBA 0.07 s for 3 frames x 16
// features (69 parameters).
//
// Synthetic data with exact ground truth (no files needed): a rectified stereo head
// (320x240, f = 300 px, baseline 0.12 m), points 1.5-10 m ahead, 0.5 px pixel noise.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <vector>

#include "vo/bundle_adjustment.h"
#include "vo/horn.h"
#include "vo/odometry.h"  // DefaultOdometryBundleAdjustmentOptions
#include "vo/ransac.h"

namespace {

constexpr double kPixelSigma = 0.5;

double Normal(vo::SplitMix64* rng) {
  const double u1 = 1.0 - rng->Uniform();
  const double u2 = rng->Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

vo::StereoCamera Camera() {
  vo::StereoCamera cam;
  cam.fx_px = cam.fy_px = 300.0;
  cam.cx_px = 159.5;
  cam.cy_px = 119.5;
  cam.baseline_m = 0.12;
  return cam;
}

bool InImage(const Eigen::Vector2d& uv) {
  return uv.x() >= 0.0 && uv.y() >= 0.0 && uv.x() <= 319.0 && uv.y() <= 239.0;
}

// Frame i of a forward motion with a slight turn: p_world = T_world_cam0(i) * p_cam0.
Eigen::Isometry3d PoseOfFrame(int i) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.035 * i, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.01 * i, 0.0, 0.15 * i);
  return T;
}

void BM_Horn100Points(benchmark::State& state) {
  vo::SplitMix64 rng(1);
  Eigen::Matrix3Xd src(3, 100);
  for (int i = 0; i < 100; ++i)
    src.col(i) = Eigen::Vector3d(4.0 * rng.Uniform() - 2.0, 2.0 * rng.Uniform() - 1.0,
                                 1.5 + 8.0 * rng.Uniform());
  const Eigen::Isometry3d T = PoseOfFrame(1).inverse();
  Eigen::Matrix3Xd dst = T * src;
  for (int i = 0; i < 100; ++i)
    dst.col(i) += 0.01 * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
  for (auto _ : state) {
    const vo::HornResult r = vo::EstimateRigidMotionHorn(src, dst);
    benchmark::DoNotOptimize(r.T_dst_src);
  }
}
BENCHMARK(BM_Horn100Points)->Unit(benchmark::kMicrosecond);

// 300 stereo correspondences between frames 0 and 1, 30% with a random current observation.
std::vector<vo::StereoCorrespondence> RansacData() {
  const vo::StereoCamera cam = Camera();
  const Eigen::Isometry3d T_curr_prev = PoseOfFrame(1).inverse();
  vo::SplitMix64 rng(2);
  std::vector<vo::StereoCorrespondence> corr;
  while (corr.size() < 300) {
    const Eigen::Vector3d p_prev = cam.BackprojectDepth(
        319.0 * rng.Uniform(), 239.0 * rng.Uniform(), 1.5 + 8.5 * rng.Uniform());
    const Eigen::Vector3d p_curr = T_curr_prev * p_prev;
    Eigen::Vector2d lp, rp, l, r;
    cam.ProjectLeft(p_prev, &lp);
    cam.ProjectRight(p_prev, &rp);
    if (!cam.ProjectLeft(p_curr, &l) || !cam.ProjectRight(p_curr, &r) || !InImage(l) ||
        !InImage(r) || !InImage(rp))
      continue;
    vo::StereoCorrespondence c;
    c.uv_prev_px = lp + kPixelSigma * Eigen::Vector2d(Normal(&rng), Normal(&rng));
    c.disparity_prev_px = c.uv_prev_px.x() - (rp.x() + kPixelSigma * Normal(&rng));
    const bool outlier = rng.Uniform() < 0.3;
    if (outlier) {
      c.uv_curr_px = Eigen::Vector2d(319.0 * rng.Uniform(), 239.0 * rng.Uniform());
      c.disparity_curr_px = 2.0 + 30.0 * rng.Uniform();
    } else {
      c.uv_curr_px = l + kPixelSigma * Eigen::Vector2d(Normal(&rng), Normal(&rng));
      c.disparity_curr_px = c.uv_curr_px.x() - (r.x() + kPixelSigma * Normal(&rng));
    }
    if (!(c.disparity_prev_px > 0.5) || !(c.disparity_curr_px > 0.5)) continue;
    c.p_prev_cam0 = cam.Backproject(c.uv_prev_px.x(), c.uv_prev_px.y(), c.disparity_prev_px);
    c.track_age = static_cast<int>(rng.UniformIndex(6));
    corr.push_back(c);
  }
  return corr;
}

// Arg: 0 = Horn refit only, 1 = + reprojection refinement with fixed points, 2 = + two-frame
// refinement (the default).
void BM_Ransac300Matches30PercentOutliers(benchmark::State& state) {
  const std::vector<vo::StereoCorrespondence> corr = RansacData();
  vo::RansacOptions options;
  options.inlier_threshold_px = 3.0;
  options.refine_nonlinear = state.range(0) >= 1;
  options.refine_points = state.range(0) >= 2;
  vo::RansacResult r;
  for (auto _ : state) {
    r = vo::EstimateMotionRansac(Camera(), corr, options);
    benchmark::DoNotOptimize(r.T_prev_curr);
  }
  state.counters["iterations"] = r.num_iterations;
  state.counters["inliers"] = r.num_inliers;
  state.counters["t_err_mm"] =
      1e3 * (r.T_prev_curr.translation() - PoseOfFrame(1).translation()).norm();
}
BENCHMARK(BM_Ransac300Matches30PercentOutliers)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond);

// A window of num_frames frames and num_points points seen in >= 2 frames, stereo
// observations with noise, start perturbed (2 cm / ~0.6 deg per pose, 5 cm per point).
vo::BundleAdjustmentProblem BaData(int num_frames, int num_points) {
  const vo::StereoCamera cam = Camera();
  vo::SplitMix64 rng(3);
  vo::BundleAdjustmentProblem p;
  for (int i = 0; i < num_frames; ++i) p.T_world_cam0.push_back(PoseOfFrame(i));
  while (static_cast<int>(p.points_world.size()) < num_points) {
    const Eigen::Vector3d x(6.0 * rng.Uniform() - 3.0, 3.0 * rng.Uniform() - 1.5,
                            2.0 + 8.0 * rng.Uniform());
    std::vector<vo::BaObservation> obs;
    for (int i = 0; i < num_frames; ++i) {
      const Eigen::Vector3d p_cam0 = p.T_world_cam0[i].inverse() * x;
      vo::BaObservation o;
      Eigen::Vector2d l, r;
      if (!cam.ProjectLeft(p_cam0, &l) || !cam.ProjectRight(p_cam0, &r) || !InImage(l) ||
          !InImage(r))
        continue;
      const double v_noise = kPixelSigma * Normal(&rng);
      o.frame_index = i;
      o.point_index = static_cast<int>(p.points_world.size());
      o.uv_left_px = l + Eigen::Vector2d(kPixelSigma * Normal(&rng), v_noise);
      o.has_right = true;
      o.uv_right_px = r + Eigen::Vector2d(kPixelSigma * Normal(&rng), v_noise);
      obs.push_back(o);
    }
    if (obs.size() < 2) continue;
    p.points_world.push_back(x + 0.05 * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng)));
    p.observations.insert(p.observations.end(), obs.begin(), obs.end());
  }
  for (int i = 1; i < num_frames; ++i) {
    const Eigen::Vector3d axis(Normal(&rng), Normal(&rng), Normal(&rng));
    p.T_world_cam0[i].linear() =
        (Eigen::AngleAxisd(0.01, axis.normalized()) * p.T_world_cam0[i].linear()).eval();
    p.T_world_cam0[i].translation() +=
        0.02 * Eigen::Vector3d(Normal(&rng), Normal(&rng), Normal(&rng));
  }
  return p;
}

// Args: frames, points, solver (0 = Ceres SPARSE_SCHUR, 1 = Ceres DENSE_SCHUR, 2 = schur_lm),
// settings (0 = BundleAdjustmentOptions defaults, 1 = the pipeline's,
// DefaultOdometryBundleAdjustmentOptions: two-frame points, 10 iterations).
void BM_BundleAdjustment(benchmark::State& state) {
  const vo::BundleAdjustmentProblem problem =
      BaData(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  vo::BundleAdjustmentOptions options = state.range(3) == 1
                                            ? vo::DefaultOdometryBundleAdjustmentOptions()
                                            : vo::BundleAdjustmentOptions();
  options.solver = state.range(2) == 2 ? vo::BaSolver::kSchurLm : vo::BaSolver::kCeres;
  options.linear_solver =
      state.range(2) == 0 ? vo::BaLinearSolver::kSparseSchur : vo::BaLinearSolver::kDenseSchur;
  vo::BundleAdjustmentSummary s;
  for (auto _ : state) {
    s = vo::RunBundleAdjustment(Camera(), problem, options);
    benchmark::DoNotOptimize(s.final_cost);
  }
  state.counters["iterations"] = s.num_iterations;
  state.counters["observations"] = s.num_residual_blocks;
  state.counters["parameters"] = 7.0 * state.range(0) + 3.0 * state.range(1);
  state.counters["rms_before_px"] = s.rms_reprojection_before_px;
  state.counters["rms_after_px"] = s.rms_reprojection_after_px;
  state.SetLabel(s.linear_solver);
}
BENCHMARK(BM_BundleAdjustment)
    ->ArgNames({"frames", "points", "solver", "pipeline"})
    ->Args({5, 150, 0, 0})
    ->Args({5, 150, 1, 0})
    ->Args({5, 150, 2, 0})
    ->Args({3, 16, 0, 0})
    ->Args({3, 16, 1, 0})
    ->Args({3, 16, 2, 0})
    ->Args({10, 300, 0, 0})
    ->Args({10, 300, 1, 0})
    ->Args({10, 300, 2, 0})
    ->Args({5, 100, 1, 1})
    ->Args({5, 100, 2, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  std::printf(
      "backend_bench: synthetic stereo data, single thread (Ceres num_threads = 1; schur_lm is "
      "single-threaded)\n");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
