// Front-end timings at the paper's resolution (320x240), single thread: Harris and SIFT
// detection, dense disparity (StereoBM with the post-filters, SGBM for comparison), depth
// attachment. Paper (Pentium IV 2.4 GHz): corners 0.04 s, SIFT 0.94 s per frame.
//
// Input: Middlebury tsukuba (im3/im4) resized to 320x240 when the shared data folder is
// present, otherwise a synthetic random texture shifted by 8 px.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "vo/disparity.h"
#include "vo/features.h"

namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;

struct StereoPair {
  cv::Mat left, right;  // CV_8UC1, 320x240
  std::string source;
};

StereoPair LoadPair() {
  StereoPair p;
  const std::string dir = std::string(VOBENCH_SHARED_DATA_DIR) + "/middlebury/tsukuba/";
  const cv::Mat left = cv::imread(dir + "im3.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(dir + "im4.png", cv::IMREAD_GRAYSCALE);
  if (!left.empty() && !right.empty()) {
    cv::resize(left, p.left, cv::Size(kWidth, kHeight), 0, 0, cv::INTER_AREA);
    cv::resize(right, p.right, cv::Size(kWidth, kHeight), 0, 0, cv::INTER_AREA);
    p.source = "middlebury tsukuba resized to 320x240";
    return p;
  }
  constexpr int kShiftPx = 8;
  cv::Mat noise(kHeight, kWidth + kShiftPx, CV_32F);
  cv::RNG rng(1);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.5);
  cv::normalize(noise, noise, 0.0, 255.0, cv::NORM_MINMAX);
  cv::Mat texture;
  noise.convertTo(texture, CV_8U);
  p.left = texture(cv::Rect(0, 0, kWidth, kHeight)).clone();
  p.right = texture(cv::Rect(kShiftPx, 0, kWidth, kHeight)).clone();
  p.source = "synthetic texture (no Middlebury data)";
  return p;
}

const StereoPair& Pair() {
  static const StereoPair pair = LoadPair();
  return pair;
}

void RunDetector(benchmark::State& state, const vo::DetectorOptions& options) {
  std::unique_ptr<vo::FeatureDetector> detector = vo::CreateFeatureDetector(options);
  if (!detector) {
    state.SkipWithError("invalid detector options");
    return;
  }
  size_t n = 0;
  for (auto _ : state) {
    const vo::FeatureSet set = detector->DetectWithDescriptors(Pair().left);
    n = set.features.size();
    benchmark::DoNotOptimize(set.features.data());
  }
  state.counters["features"] = static_cast<double>(n);
}

void BM_Harris(benchmark::State& state) { RunDetector(state, vo::DetectorOptions()); }
BENCHMARK(BM_Harris)->Unit(benchmark::kMillisecond);

void BM_HarrisSubpixel(benchmark::State& state) {
  vo::DetectorOptions options;
  options.harris.subpixel = true;
  RunDetector(state, options);
}
BENCHMARK(BM_HarrisSubpixel)->Unit(benchmark::kMillisecond);

void BM_HarrisBucketed(benchmark::State& state) {
  vo::DetectorOptions options;
  options.bucket_cols = 8;
  options.bucket_rows = 6;
  options.max_per_bucket = 8;
  RunDetector(state, options);
}
BENCHMARK(BM_HarrisBucketed)->Unit(benchmark::kMillisecond);

void BM_Sift(benchmark::State& state) {
  vo::DetectorOptions options;
  options.type = vo::DetectorType::kSift;
  RunDetector(state, options);
}
BENCHMARK(BM_Sift)->Unit(benchmark::kMillisecond);

// Arguments: num_disparities, left-right check on/off.
void RunDisparity(benchmark::State& state, vo::DisparityOptions options) {
  options.num_disparities = static_cast<int>(state.range(0));
  if (state.range(1) == 0) options.left_right_max_diff_px = -1.0;
  vo::DisparityEstimator estimator(options);
  double valid = 0.0;
  for (auto _ : state) {
    const vo::DisparityResult r = estimator.Compute(Pair().left, Pair().right);
    if (!r.ok) {
      state.SkipWithError(r.message.c_str());
      return;
    }
    valid = static_cast<double>(r.num_valid) / (kWidth * kHeight);
    benchmark::DoNotOptimize(r.disparity_px.data);
  }
  state.counters["valid_fraction"] = valid;
}

void BM_DisparityBlockMatching(benchmark::State& state) {
  RunDisparity(state, vo::DisparityOptions());
}
BENCHMARK(BM_DisparityBlockMatching)
    ->ArgNames({"ndisp", "lr"})
    ->Args({32, 1})
    ->Args({48, 1})
    ->Args({64, 1})
    ->Args({64, 0})
    ->Unit(benchmark::kMillisecond);

// Our block matcher: both views from one cost volume (the pipeline's default).
void BM_DisparityOneVolume(benchmark::State& state) {
  vo::DisparityOptions options;
  options.algorithm = vo::DisparityAlgorithm::kBlockMatchingOneVolume;
  RunDisparity(state, options);
}
BENCHMARK(BM_DisparityOneVolume)
    ->ArgNames({"ndisp", "lr"})
    ->Args({32, 1})
    ->Args({48, 1})
    ->Args({64, 1})
    ->Args({64, 0})
    ->Unit(benchmark::kMillisecond);

void BM_DisparitySemiGlobal(benchmark::State& state) {
  vo::DisparityOptions options;
  options.algorithm = vo::DisparityAlgorithm::kSemiGlobal;
  options.block_size = 5;
  RunDisparity(state, options);
}
BENCHMARK(BM_DisparitySemiGlobal)
    ->ArgNames({"ndisp", "lr"})
    ->Args({32, 1})
    ->Args({64, 1})
    ->Args({64, 0})
    ->Unit(benchmark::kMillisecond);

void BM_AttachDepth(benchmark::State& state) {
  const vo::DisparityResult r = vo::ComputeDisparity(Pair().left, Pair().right);
  const std::vector<vo::Feature> features =
      vo::CreateFeatureDetector(vo::DetectorOptions())->Detect(Pair().left);
  vo::StereoCamera cam;
  cam.fx_px = cam.fy_px = 300.0;
  cam.cx_px = (kWidth - 1) / 2.0;
  cam.cy_px = (kHeight - 1) / 2.0;
  cam.baseline_m = 0.12;
  for (auto _ : state) {
    std::vector<vo::Feature> copy = features;
    vo::AttachDepth(r.disparity_px, cam, &copy);
    vo::DropFeaturesWithoutDepth(&copy);
    benchmark::DoNotOptimize(copy.data());
  }
  state.counters["features"] = static_cast<double>(features.size());
}
BENCHMARK(BM_AttachDepth)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  // Single-thread figures, comparable with the paper's single-core timings.
  cv::setNumThreads(1);
  std::printf("frontend_bench input: %s\n", Pair().source.c_str());
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
