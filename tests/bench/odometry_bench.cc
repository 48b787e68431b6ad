// Whole-pipeline timing: StereoOdometry::Process per frame at the paper's resolution (320x240),
// single thread (cv::setNumThreads(1); Ceres runs single-threaded anyway). Target (the issue):
// median VO time per frame <= 15 ms. Paper (Pentium IV 2.4 GHz): the whole system ≈ 3.5 Hz.
//
// Input: a synthetic sequence like the simulator's L-hallway run (the hallway rig: 320x240,
// fx = 230 px, baseline 0.09 m; 10 Hz): a ray-cast textured corridor, 20 frames driving
// forward at 4 cm per frame, then 20 frames turning in place at 3° per frame. Every benchmark
// iteration processes the whole sequence from a fresh StereoOdometry; the counters report the
// median over all frames of the total and of each stage (milliseconds), and the final pose
// error against the ground truth.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "vo/odometry.h"

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kForwardFrames = 20;
constexpr int kTurnFrames = 20;

// The camera rigs of results/speed/ (as the simulator renders them): 0 = the hallway head
// (320x240, fx 230 px, 0.09 m; the L-hallway rig), 1 = the same at 640x480, 2 = EuRoC-like
// (752x480, fx 458 px, 0.11 m), 3 = KITTI-like (1241x376, fx 718 px, 0.54 m).
vo::StereoCamera RigCamera(int rig) {
  struct Rig {
    int width, height;
    double fx, baseline;
  };
  static const Rig rigs[] = {{320, 240, 230.0, 0.09},
                             {640, 480, 460.0, 0.09},
                             {752, 480, 458.0, 0.11},
                             {1241, 376, 718.0, 0.54}};
  const Rig& r = rigs[rig];
  vo::StereoCamera cam;
  cam.width = r.width;
  cam.height = r.height;
  cam.fx_px = cam.fy_px = r.fx;
  cam.cx_px = (r.width - 1) / 2.0;
  cam.cy_px = (r.height - 1) / 2.0;
  cam.baseline_m = r.baseline;
  return cam;
}

// A corridor box in the hallway frame (x along, y left, z up), one random texture per face
// (1 cm texels, blurred noise at two scales), ray-cast with 2 × 2 supersampling.
class Corridor {
 public:
  Corridor() {
    const double lo[3] = {-3.0, -1.2, 0.0}, hi[3] = {12.0, 1.2, 2.6};
    const int axes[6][3] = {{2, 0, 1}, {2, 0, 1}, {1, 0, 2}, {1, 0, 2}, {0, 1, 2}, {0, 1, 2}};
    cv::RNG rng(11);
    for (int k = 0; k < 6; ++k) {
      Face f;
      f.axis = axes[k][0];
      f.a = axes[k][1];
      f.b = axes[k][2];
      f.position = k % 2 == 0 ? lo[f.axis] : hi[f.axis];
      f.origin_a = lo[f.a];
      f.origin_b = lo[f.b];
      const int cols = static_cast<int>((hi[f.a] - lo[f.a]) / kTexel) + 2;
      const int rows = static_cast<int>((hi[f.b] - lo[f.b]) / kTexel) + 2;
      cv::Mat fine(rows, cols, CV_32F), coarse(rows / 8 + 1, cols / 8 + 1, CV_32F);
      rng.fill(fine, cv::RNG::UNIFORM, 0.0, 1.0);
      rng.fill(coarse, cv::RNG::UNIFORM, 0.0, 1.0);
      cv::GaussianBlur(fine, fine, cv::Size(0, 0), 2.0);
      cv::resize(coarse, coarse, fine.size(), 0, 0, cv::INTER_CUBIC);
      f.texture = 0.6 * fine + 0.4 * coarse;
      cv::normalize(f.texture, f.texture, 20.0, 235.0, cv::NORM_MINMAX);
      faces_.push_back(f);
    }
  }

  cv::Mat Render(const vo::StereoCamera& cam, const Eigen::Isometry3d& T_hall_cam) const {
    cv::Mat image(cam.height, cam.width, CV_8UC1);
    const Eigen::Matrix3d R = T_hall_cam.linear();
    const Eigen::Vector3d o = T_hall_cam.translation();
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        double sum = 0.0;
        for (int s = 0; s < 4; ++s) {
          const Eigen::Vector3d d_cam((u - 0.25 + 0.5 * (s % 2) - cam.cx_px) / cam.fx_px,
                                      (v - 0.25 + 0.5 * (s / 2) - cam.cy_px) / cam.fy_px, 1.0);
          sum += Sample(o, R * d_cam);
        }
        image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(sum / 4.0);
      }
    }
    return image;
  }

 private:
  static constexpr double kTexel = 0.01;  // metres per texel
  struct Face {
    int axis = 0, a = 0, b = 0;
    double position = 0.0, origin_a = 0.0, origin_b = 0.0;
    cv::Mat texture;
  };

  double Sample(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double best_t = 1e9;
    const Face* best = nullptr;
    for (const Face& f : faces_) {
      if (std::abs(d[f.axis]) < 1e-12) continue;
      const double t = (f.position - o[f.axis]) / d[f.axis];
      if (t > 1e-6 && t < best_t) {
        best_t = t;
        best = &f;
      }
    }
    if (best == nullptr) return 0.0;
    const Eigen::Vector3d p = o + best_t * d;
    const double x = (p[best->a] - best->origin_a) / kTexel;
    const double y = (p[best->b] - best->origin_b) / kTexel;
    const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, best->texture.cols - 2);
    const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, best->texture.rows - 2);
    const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
    const float* r0 = best->texture.ptr<float>(y0);
    const float* r1 = best->texture.ptr<float>(y0 + 1);
    return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) +
           fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  }

  std::vector<Face> faces_;
};

// Frame i: forward along the corridor, then an in-place turn to the left.
Eigen::Isometry3d PoseOfFrame(int i) {
  Eigen::Matrix3d R_level;  // cv camera axes in the hallway frame, looking along +x
  R_level.col(0) = Eigen::Vector3d(0, -1, 0);
  R_level.col(1) = Eigen::Vector3d(0, 0, -1);
  R_level.col(2) = Eigen::Vector3d(1, 0, 0);
  const int forward = std::min(i, kForwardFrames - 1);
  const double yaw = std::max(0, i - (kForwardFrames - 1)) * 3.0 * kDeg;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_level;
  T.translation() = Eigen::Vector3d(0.04 * forward, 0.0, 0.8);
  return T;
}

struct Sequence {
  std::vector<cv::Mat> left, right;
  std::vector<Eigen::Isometry3d> T_hall_cam0;
};

const Sequence& TheSequence(int rig = 0) {
  static std::map<int, Sequence> sequences;
  auto it = sequences.find(rig);
  if (it != sequences.end()) return it->second;
  const Sequence sequence = [rig] {
    static const Corridor corridor;
    const vo::StereoCamera cam = RigCamera(rig);
    Eigen::Isometry3d T_cam0_cam1 = Eigen::Isometry3d::Identity();
    T_cam0_cam1.translation().x() = cam.baseline_m;
    Sequence s;
    for (int i = 0; i < kForwardFrames + kTurnFrames; ++i) {
      s.T_hall_cam0.push_back(PoseOfFrame(i));
      s.left.push_back(corridor.Render(cam, s.T_hall_cam0.back()));
      s.right.push_back(corridor.Render(cam, s.T_hall_cam0.back() * T_cam0_cam1));
    }
    return s;
  }();
  return sequences.emplace(rig, sequence).first->second;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void RunPipeline(benchmark::State& state, const vo::OdometryOptions& options, int rig = 0) {
  const Sequence& seq = TheSequence(rig);
  const size_t n = seq.left.size();
  std::vector<double> total, disparity, detect, depth, match, motion, ba;
  int lost = 0;
  double end_error_m = 0.0, end_error_deg = 0.0;
  for (auto _ : state) {
    vo::StereoOdometry vo(RigCamera(rig), options);
    std::vector<vo::OdometryResult> results;
    for (size_t i = 0; i < n; ++i) {
      results.push_back(vo.Process(seq.left[i], seq.right[i], 0.1 * i));
      const vo::StageTimes& t = results.back().times;
      if (i == 0) continue;  // the first frame initialises (plane orientation): not a VO step
      total.push_back(t.total_ms);
      disparity.push_back(t.disparity_ms);
      detect.push_back(t.detect_ms);
      depth.push_back(t.depth_ms);
      match.push_back(t.match_ms);
      motion.push_back(t.motion_ms);
      ba.push_back(t.ba_ms);
      lost += results.back().status == vo::TrackingStatus::kLost;
    }
    // End-pose error of the motion since the first frame.
    const Eigen::Isometry3d est = results[0].T_world_cam0.inverse() * results[n - 1].T_world_cam0;
    const Eigen::Isometry3d gt = seq.T_hall_cam0[0].inverse() * seq.T_hall_cam0[n - 1];
    end_error_m = (est.translation() - gt.translation()).norm();
    end_error_deg = Eigen::AngleAxisd(est.linear().transpose() * gt.linear()).angle() / kDeg;
  }
  state.counters["median_ms"] = Median(total);
  state.counters["disparity_ms"] = Median(disparity);
  state.counters["detect_ms"] = Median(detect);
  state.counters["depth_ms"] = Median(depth);
  state.counters["match_ms"] = Median(match);
  state.counters["motion_ms"] = Median(motion);
  state.counters["ba_ms"] = Median(ba);
  state.counters["lost"] = lost / static_cast<double>(state.iterations());
  state.counters["end_err_mm"] = 1e3 * end_error_m;
  state.counters["end_err_deg"] = end_error_deg;
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}

void BM_OdometryDefault(benchmark::State& state) { RunPipeline(state, vo::OdometryOptions()); }
BENCHMARK(BM_OdometryDefault)->Unit(benchmark::kMillisecond)->Iterations(3);

// The whole pipeline at the four camera sizes of results/speed/. Args: rig (RigCamera), disparity
// mode (0 = at_features, the default; 1 = dense).
void BM_OdometryAtSize(benchmark::State& state) {
  vo::OdometryOptions options;
  options.front_end.disparity_mode =
      state.range(1) == 0 ? vo::DisparityMode::kAtFeatures : vo::DisparityMode::kDense;
  const vo::StereoCamera cam = RigCamera(static_cast<int>(state.range(0)));
  state.SetLabel(std::to_string(cam.width) + "x" + std::to_string(cam.height) + " " +
                 vo::ToString(options.front_end.disparity_mode));
  RunPipeline(state, options, static_cast<int>(state.range(0)));
}
BENCHMARK(BM_OdometryAtSize)
    ->ArgNames({"rig", "dense"})
    ->ArgsProduct({{0, 1, 2, 3}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

void BM_OdometryNoBundleAdjustment(benchmark::State& state) {
  vo::OdometryOptions options;
  options.back_end.bundle_adjustment = false;
  RunPipeline(state, options);
}
BENCHMARK(BM_OdometryNoBundleAdjustment)->Unit(benchmark::kMillisecond)->Iterations(3);

// Without the disparity's left-right check (one StereoBM pass instead of two): the RANSAC
// inlier test, which checks every point in both current images, catches most of what it removes.
void BM_OdometryNoLeftRightCheck(benchmark::State& state) {
  vo::OdometryOptions options;
  options.front_end.disparity.left_right_max_diff_px = -1.0;
  RunPipeline(state, options);
}
BENCHMARK(BM_OdometryNoLeftRightCheck)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_OdometryWindow10(benchmark::State& state) {
  vo::OdometryOptions options;
  options.back_end.window_frames = 10;
  RunPipeline(state, options);
}
BENCHMARK(BM_OdometryWindow10)->Unit(benchmark::kMillisecond)->Iterations(3);

// Arg: the matcher (vo::MatcherType as int).
void BM_OdometryMatcher(benchmark::State& state) {
  vo::OdometryOptions options;
  options.tracker.matcher.type = static_cast<vo::MatcherType>(state.range(0));
  state.SetLabel(vo::ToString(options.tracker.matcher.type));
  RunPipeline(state, options);
}
BENCHMARK(BM_OdometryMatcher)
    ->Arg(static_cast<int>(vo::MatcherType::kSvdProximity))
    ->Arg(static_cast<int>(vo::MatcherType::kSvdNcc))
    ->Arg(static_cast<int>(vo::MatcherType::kNccMutual))
    ->Arg(static_cast<int>(vo::MatcherType::kLucasKanade))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

}  // namespace

int main(int argc, char** argv) {
  // Single-thread figures, comparable with the paper's single-core timings.
  cv::setNumThreads(1);
  std::printf(
      "odometry_bench: %d frames of a synthetic 320x240 corridor (%d forward at 4 cm, "
      "%d turning in place at 3 deg)\n",
      kForwardFrames + kTurnFrames, kForwardFrames, kTurnFrames);
  TheSequence();  // render once, outside the timings
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
