// Benchmarks of the similarity cues and the inter-frame matchers (Release, one thread):
//   build/tests/matcher_bench [--benchmark_filter=Svd]
// Scene: a 640×480 random texture and its copy under a known similarity transform (2°,
// ×1.02, (6, −4) px) with noise, ~500 Shi–Tomasi corners per frame (as in svd_matcher_test).
// "Cached" = the frames' cues (NCC patches, Gabor phases, LK pyramids) were computed by an
// earlier call, as in the pipeline where the current frame becomes the previous one; "Cold"
// clears them each iteration, so it includes both frames' cue computation.
#include <benchmark/benchmark.h>

#include <Eigen/SVD>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "tests/synthetic_images.h"
#include "vo/gabor.h"
#include "vo/matcher.h"
#include "vo/ncc.h"
#include "vo/svd_matcher.h"

namespace {

using vobench_test::RandomTexture;

struct Scene {
  vo::MatchFrame prev, curr;
};

// Built once; `sift` adds SIFT keypoints and descriptors instead of corners.
const Scene& GetScene(bool sift = false) {
  static std::unique_ptr<Scene> scenes[2];
  std::unique_ptr<Scene>& s = scenes[sift ? 1 : 0];
  if (s != nullptr) return *s;
  cv::setNumThreads(1);
  s = std::make_unique<Scene>();
  const cv::Mat image = RandomTexture(640, 480, 7);
  cv::Mat A = cv::getRotationMatrix2D(cv::Point2f(320, 240), 2.0, 1.02);
  A.at<double>(0, 2) += 6.0;
  A.at<double>(1, 2) -= 4.0;
  cv::Mat warped, noisy, noise(image.size(), CV_32F);
  cv::warpAffine(image, warped, A, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  warped.convertTo(noisy, CV_32F);
  cv::RNG(8).fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
  noisy += noise;
  noisy.convertTo(warped, CV_8U);
  s->prev.image = image;
  s->curr.image = warped;
  for (vo::MatchFrame* f : {&s->prev, &s->curr}) {
    if (sift) {
      std::vector<cv::KeyPoint> keypoints;
      cv::SIFT::create(500)->detectAndCompute(f->image, cv::noArray(), keypoints, f->descriptors);
      for (const cv::KeyPoint& k : keypoints) {
        vo::Feature feature;
        feature.uv_px = Eigen::Vector2d(k.pt.x, k.pt.y);
        f->features.push_back(feature);
      }
    } else {
      std::vector<cv::Point2f> corners;
      cv::goodFeaturesToTrack(f->image, corners, 500, 0.005, 6.0);
      for (const cv::Point2f& c : corners) {
        vo::Feature feature;
        feature.uv_px = Eigen::Vector2d(c.x, c.y);
        f->features.push_back(feature);
      }
    }
  }
  return *s;
}

void Counters(benchmark::State& state, const vo::MatcherSummary& s) {
  state.counters["prev"] = s.num_prev;
  state.counters["curr"] = s.num_curr;
  state.counters["matches"] = s.num_matches;
  state.counters["candidates"] = s.num_candidates;
  if (s.num_components > 0) {
    state.counters["components"] = s.num_components;
    state.counters["largest"] = s.largest_component;
    state.counters["guard"] = s.num_guard_splits;
    state.counters["rank_deficient"] = s.num_rank_deficient;
  }
}

// ---- Cues ---------------------------------------------------------------------------------

void BM_GaborPhase500x16(benchmark::State& state) {
  const Scene& scene = GetScene();
  const vo::GaborBank bank;
  for (auto _ : state) {
    vo::GaborResponses r = bank.Compute(scene.prev.image, scene.prev.features);
    benchmark::DoNotOptimize(r.phase.data());
  }
  state.counters["features"] = scene.prev.features.size();
  state.counters["filters"] = bank.num_filters();
}
BENCHMARK(BM_GaborPhase500x16)->Unit(benchmark::kMicrosecond);

// The same at the paper's 320×240 (features scaled into the smaller image).
void BM_GaborPhase500x16_320x240(benchmark::State& state) {
  const Scene& scene = GetScene();
  cv::Mat small;
  cv::resize(scene.prev.image, small, cv::Size(320, 240), 0, 0, cv::INTER_AREA);
  std::vector<vo::Feature> features = scene.prev.features;
  for (vo::Feature& f : features) f.uv_px *= 0.5;
  const vo::GaborBank bank;
  for (auto _ : state) {
    vo::GaborResponses r = bank.Compute(small, features);
    benchmark::DoNotOptimize(r.phase.data());
  }
}
BENCHMARK(BM_GaborPhase500x16_320x240)->Unit(benchmark::kMicrosecond);

void BM_NccPatches500(benchmark::State& state) {
  const Scene& scene = GetScene();
  for (auto _ : state) {
    vo::NccPatches p;
    p.Compute(scene.prev.image, scene.prev.features, vo::NccOptions());
    benchmark::DoNotOptimize(&p);
  }
}
BENCHMARK(BM_NccPatches500)->Unit(benchmark::kMicrosecond);

// ---- Matchers -----------------------------------------------------------------------------

void RunMatcher(benchmark::State& state, vo::MatcherOptions options, bool cold, bool sift = false) {
  Scene scene = GetScene(sift);  // own copy: its cue cache is ours
  std::unique_ptr<vo::FrameMatcher> matcher = vo::CreateFrameMatcher(options);
  vo::MatcherSummary summary;
  matcher->MatchFrames(scene.prev, scene.curr, &summary);  // warm the caches
  for (auto _ : state) {
    if (cold) {
      scene.prev.ClearCues();
      scene.curr.ClearCues();
    }
    std::vector<vo::Match> m = matcher->MatchFrames(scene.prev, scene.curr, &summary);
    benchmark::DoNotOptimize(m.data());
  }
  Counters(state, summary);
}

vo::MatcherOptions Options(vo::MatcherType type, bool dense = false) {
  vo::MatcherOptions o;
  o.type = type;
  o.svd.dense = dense;
  return o;
}

void BM_SvdNccGabor_Sparse_Cached(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kSvdNccGabor), false);
}
BENCHMARK(BM_SvdNccGabor_Sparse_Cached)->Unit(benchmark::kMillisecond);

void BM_SvdNccGabor_Sparse_Cold(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kSvdNccGabor), true);
}
BENCHMARK(BM_SvdNccGabor_Sparse_Cold)->Unit(benchmark::kMillisecond);

void BM_SvdNccGabor_Dense_Cached(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kSvdNccGabor, true), false);
}
BENCHMARK(BM_SvdNccGabor_Dense_Cached)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_SvdNcc_Sparse_Cached(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kSvdNcc), false);
}
BENCHMARK(BM_SvdNcc_Sparse_Cached)->Unit(benchmark::kMillisecond);

void BM_SvdProximity_Sparse(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kSvdProximity), false);
}
BENCHMARK(BM_SvdProximity_Sparse)->Unit(benchmark::kMillisecond);

void BM_SvdProximity_Dense(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kSvdProximity, true), false);
}
BENCHMARK(BM_SvdProximity_Dense)->Unit(benchmark::kMillisecond)->Iterations(3);

// The raw dense reference step alone: BDCSVD of a 500×500 G and P = U Vᵀ.
void BM_DenseBdcsvd500(benchmark::State& state) {
  const Eigen::MatrixXd G = Eigen::MatrixXd::Random(500, 500).cwiseAbs();
  for (auto _ : state) {
    Eigen::BDCSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeThinU | Eigen::ComputeThinV);
    Eigen::MatrixXd P = svd.matrixU() * svd.matrixV().transpose();
    benchmark::DoNotOptimize(P.data());
  }
}
BENCHMARK(BM_DenseBdcsvd500)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_NccMutual_Cached(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kNccMutual), false);
}
BENCHMARK(BM_NccMutual_Cached)->Unit(benchmark::kMillisecond);

void BM_NccMutual_Cold(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kNccMutual), true);
}
BENCHMARK(BM_NccMutual_Cold)->Unit(benchmark::kMillisecond);

void BM_LucasKanade_Cached(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kLucasKanade), false);
}
BENCHMARK(BM_LucasKanade_Cached)->Unit(benchmark::kMillisecond);

void BM_LucasKanade_Cold(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kLucasKanade), true);
}
BENCHMARK(BM_LucasKanade_Cold)->Unit(benchmark::kMillisecond);

void BM_Kalman_Cached(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kKalman), false);
}
BENCHMARK(BM_Kalman_Cached)->Unit(benchmark::kMillisecond);

void BM_SiftRatio(benchmark::State& state) {
  RunMatcher(state, Options(vo::MatcherType::kSiftRatio), false, true);
}
BENCHMARK(BM_SiftRatio)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
