// Front-end timings at the paper's resolution (320x240), single thread: Harris and SIFT
// detection, dense disparity (StereoBM with the post-filters, SGBM for comparison), depth
// attachment. Paper (Pentium IV 2.4 GHz): corners 0.04 s, SIFT 0.94 s per frame.
//
// Input: Middlebury tsukuba (im3/im4) resized to 320x240 when the shared data folder is
// present, otherwise a synthetic random texture shifted by 8 px.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>

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

// ---- The pipeline's front end at the four camera sizes of results/speed/ -------------------
// Arguments: width, height, num_disparities (the pipeline's camera-derived range for the
// simulator rigs: 320x240 and 640x480 hallway heads (0.09 m) 32 and 64, EuRoC-like 752x480
// (0.11 m) 80, KITTI-like 1241x376 (0.54 m) 256). The pair is tsukuba (or the synthetic
// texture) resized to that size.

const StereoPair& PairOfSize(int width, int height) {
  static std::map<std::pair<int, int>, StereoPair> cache;
  auto it = cache.find({width, height});
  if (it == cache.end()) {
    StereoPair p;
    cv::resize(Pair().left, p.left, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
    cv::resize(Pair().right, p.right, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
    p.source = Pair().source;
    it = cache.emplace(std::make_pair(width, height), p).first;
  }
  return it->second;
}

vo::StereoCamera CameraOfSize(int width, int height) {
  vo::StereoCamera cam;
  cam.width = width;
  cam.height = height;
  cam.fx_px = cam.fy_px = 0.72 * width;
  cam.cx_px = (width - 1) / 2.0;
  cam.cy_px = (height - 1) / 2.0;
  cam.baseline_m = 0.1;
  return cam;
}

vo::DisparityOptions PipelineDisparity(int num_disparities) {
  vo::DisparityOptions o;
  o.algorithm = vo::DisparityAlgorithm::kBlockMatchingOneVolume;
  o.num_disparities = num_disparities;
  return o;
}

void SizeArgs(benchmark::internal::Benchmark* b) {
  b->ArgNames({"w", "h", "ndisp"})
      ->Args({320, 240, 32})
      ->Args({640, 480, 64})
      ->Args({752, 480, 80})
      ->Args({1241, 376, 256})
      ->Unit(benchmark::kMillisecond);
}

// The pipeline's detector (bucketed Harris, 300 features).
void BM_PipelineHarris(benchmark::State& state) {
  const StereoPair& p =
      PairOfSize(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  vo::DetectorOptions options;
  options.max_features = 300;
  options.bucket_cols = 8;
  options.bucket_rows = 6;
  options.max_per_bucket = 10;
  std::unique_ptr<vo::FeatureDetector> detector = vo::CreateFeatureDetector(options);
  size_t n = 0;
  for (auto _ : state) {
    const vo::FeatureSet set = detector->DetectWithDescriptors(p.left);
    n = set.features.size();
    benchmark::DoNotOptimize(set.features.data());
  }
  state.counters["features"] = static_cast<double>(n);
}
BENCHMARK(BM_PipelineHarris)->Apply(SizeArgs);

// The Harris response alone (vo::HarrisResponse, the detector's fast path: two cv::Sobel, the
// integer block sums, the float pass), with AVX2 (arg avx2 1, where the CPU has it) and without
// (0, the SSE2 build): the same values (HarrisTest), this is their cost.
void BM_HarrisResponse(benchmark::State& state) {
  const StereoPair& p =
      PairOfSize(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const bool avx2 = state.range(2) != 0;
  cv::Mat response;
  for (auto _ : state) {
    vo::HarrisResponse(p.left, vo::HarrisOptions(), &response, avx2);
    benchmark::DoNotOptimize(response.data);
  }
}
BENCHMARK(BM_HarrisResponse)
    ->ArgNames({"w", "h", "avx2"})
    ->Args({320, 240, 0})
    ->Args({320, 240, 1})
    ->Args({1241, 376, 0})
    ->Args({1241, 376, 1})
    ->Unit(benchmark::kMicrosecond);

// The dense map (disparity_mode dense).
void BM_PipelineDisparityDense(benchmark::State& state) {
  const StereoPair& p =
      PairOfSize(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  vo::DisparityEstimator estimator(PipelineDisparity(static_cast<int>(state.range(2))));
  for (auto _ : state) {
    const vo::DisparityResult r = estimator.Compute(p.left, p.right);
    benchmark::DoNotOptimize(r.disparity_px.data);
  }
}
BENCHMARK(BM_PipelineDisparityDense)->Apply(SizeArgs);

// disparity_mode at_features: prepare the pair, then the depth of the detected features.
void BM_PipelineDisparityAtFeatures(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  const StereoPair& p = PairOfSize(w, h);
  vo::DetectorOptions detector_options;
  detector_options.max_features = 300;
  detector_options.bucket_cols = 8;
  detector_options.bucket_rows = 6;
  detector_options.max_per_bucket = 10;
  const std::vector<vo::Feature> features =
      vo::CreateFeatureDetector(detector_options)->Detect(p.left);
  const vo::StereoCamera cam = CameraOfSize(w, h);
  vo::DisparityEstimator estimator(PipelineDisparity(static_cast<int>(state.range(2))));
  int pixels = 0, with_depth = 0;
  for (auto _ : state) {
    estimator.PrepareAtPixels(p.left, p.right);
    std::vector<vo::Feature> copy = features;
    with_depth = vo::AttachDepth(&estimator, cam, &copy).num_with_depth;
    pixels = estimator.pixel_counts().left + estimator.pixel_counts().right;
    benchmark::DoNotOptimize(copy.data());
  }
  state.counters["features"] = static_cast<double>(features.size());
  state.counters["with_depth"] = with_depth;
  state.counters["pixels"] = pixels;
}
BENCHMARK(BM_PipelineDisparityAtFeatures)->Apply(SizeArgs);

// Its fixed part alone (prefiltered, padded views; the caches).
void BM_PipelineDisparityPrepare(benchmark::State& state) {
  const StereoPair& p =
      PairOfSize(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  vo::DisparityEstimator estimator(PipelineDisparity(static_cast<int>(state.range(2))));
  for (auto _ : state) {
    const vo::DisparityResult r = estimator.PrepareAtPixels(p.left, p.right);
    benchmark::DoNotOptimize(r.ok);
  }
}
BENCHMARK(BM_PipelineDisparityPrepare)->Apply(SizeArgs);

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
