// Gabor bank of eqs. (3)–(4) and the phase similarity of eq. (5).
#include "vo/gabor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace vo {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Phase of a translated sinusoid: kernel truncation, 8-bit quantisation of the image and the
// half-resolution prefilter leave a few hundredths of a radian.
constexpr double kPhaseTolRad = 0.05;
constexpr double kAmplitudeRelTol = 0.1;  // truncated, discretised envelope

// Sinusoid of wavelength λ along θ, shifted by `shift_px` along θ:
// I(p) = 128 + A cos(2π (p·n_θ − shift) / λ + φ0), rounded to 8 bits.
cv::Mat Sinusoid(double lambda, double theta, double shift_px, double amplitude = 60.0,
                 double phi0 = 0.3, int width = 160, int height = 120) {
  cv::Mat image(height, width, CV_8U);
  const double c = std::cos(theta), s = std::sin(theta);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double r1 = x * c + y * s - shift_px;
      image.at<uint8_t>(y, x) =
          cv::saturate_cast<uint8_t>(128.0 + amplitude * std::cos(2.0 * kPi * r1 / lambda + phi0));
    }
  }
  return image;
}

Feature At(double u, double v) {
  Feature f;
  f.uv_px = Eigen::Vector2d(u, v);
  return f;
}

double Theta(const GaborOptions& o, int k) {
  return kPi * (k % o.num_orientations) / o.num_orientations;
}
double Lambda(const GaborOptions& o, int k) { return o.wavelengths_px[k / o.num_orientations]; }

// Translating the pattern by δ along θ raises the phase of the (θ, λ) filter by 2πδ/λ, for
// every filter of the bank (both resolutions), at an integer and at a sub-pixel position.
TEST(GaborTest, TranslatedSinusoidShiftsPhaseBy2PiDeltaOverLambda) {
  const GaborBank bank;
  const GaborOptions& o = bank.options();
  ASSERT_EQ(bank.num_filters(), 16);
  const std::vector<Feature> features = {At(80, 60), At(79.4, 61.3)};
  for (int k = 0; k < bank.num_filters(); ++k) {
    const double theta = Theta(o, k), lambda = Lambda(o, k);
    const GaborResponses base = bank.Compute(Sinusoid(lambda, theta, 0.0), features);
    for (double delta : {0.5, 1.0, 1.7, 0.4 * lambda}) {
      const GaborResponses moved = bank.Compute(Sinusoid(lambda, theta, delta), features);
      for (int i = 0; i < 2; ++i) {
        const double expected = std::remainder(2.0 * kPi * delta / lambda, 2.0 * kPi);
        const double got = std::remainder(moved.phase_of(i)[k] - base.phase_of(i)[k], 2.0 * kPi);
        EXPECT_NEAR(std::remainder(got - expected, 2.0 * kPi), 0.0, kPhaseTolRad)
            << "filter " << k << " θ " << theta << " λ " << lambda << " δ " << delta << " feature "
            << i;
      }
    }
  }
}

// Moving the evaluation point by δ along θ lowers the phase by 2πδ/λ: the sub-pixel
// correction makes the phase a continuous function of the feature position.
TEST(GaborTest, SubPixelFeaturePositionIsApplied) {
  const GaborBank bank;
  const GaborOptions& o = bank.options();
  for (int k = 0; k < bank.num_filters(); ++k) {
    const double theta = Theta(o, k), lambda = Lambda(o, k);
    const cv::Mat image = Sinusoid(lambda, theta, 0.0);
    const double d = 0.37;
    const std::vector<Feature> features = {At(80, 60),
                                           At(80 + d * std::cos(theta), 60 + d * std::sin(theta))};
    const GaborResponses r = bank.Compute(image, features);
    const double got = std::remainder(r.phase_of(1)[k] - r.phase_of(0)[k], 2.0 * kPi);
    EXPECT_NEAR(got, -2.0 * kPi * d / lambda, kPhaseTolRad) << "filter " << k;
  }
}

TEST(GaborTest, AmplitudeMatchesSinusoidAndIgnoresBrightnessOffset) {
  const GaborBank bank;
  const GaborOptions& o = bank.options();
  constexpr double kAmplitude = 60.0;
  for (int k = 0; k < bank.num_filters(); ++k) {
    const double theta = Theta(o, k), lambda = Lambda(o, k);
    const cv::Mat image = Sinusoid(lambda, theta, 0.0, kAmplitude);
    const GaborResponses r = bank.Compute(image, {At(80, 60)});
    // Half-resolution filters see the binomial prefilter's attenuation cos⁴(π/λ).
    const double gain =
        bank.level(k / o.num_orientations) == 1 ? std::pow(std::cos(kPi / lambda), 4.0) : 1.0;
    EXPECT_NEAR(r.amplitude_of(0)[k] / (kAmplitude * gain), 1.0, kAmplitudeRelTol)
        << "filter " << k;
    // Zero-DC kernels: a brightness offset leaves the response unchanged.
    cv::Mat brighter;
    image.convertTo(brighter, CV_8U, 1.0, -40.0);
    const GaborResponses rb = bank.Compute(brighter, {At(80, 60)});
    constexpr double kOffsetTol = 1e-3;  // float accumulation only
    EXPECT_NEAR(std::remainder(rb.phase_of(0)[k] - r.phase_of(0)[k], 2 * kPi), 0.0, kOffsetTol);
    EXPECT_NEAR(rb.amplitude_of(0)[k], r.amplitude_of(0)[k], kOffsetTol * kAmplitude);
  }
}

TEST(GaborTest, SimilarityOfIdenticalFeaturesIsOne) {
  cv::Mat texture(120, 160, CV_8U);
  cv::randu(texture, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(), 1.5);
  const GaborBank bank;
  const std::vector<Feature> features = {At(40, 40), At(100, 70), At(70.3, 55.8)};
  const GaborResponses r = bank.Compute(texture, features);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(GaborPhaseSimilarity(r, i, r, i), 1.0);
  // Different places: lower, but inside [e^{−βπ}, 1].
  const double beta = bank.options().phase_exponent;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double s = GaborPhaseSimilarity(r, i, r, j);
      EXPECT_GE(s, std::exp(-beta * kPi));
      EXPECT_LE(s, 1.0);
      if (i != j) {
        EXPECT_LT(s, 0.9);
      }
    }
  }
}

TEST(GaborTest, PhaseDifferenceWrapsAroundPi) {
  constexpr double kWrapTol = 1e-12;
  EXPECT_NEAR(WrappedPhaseDiff(kPi - 0.1, -kPi + 0.1), 0.2, kWrapTol);  // not 2π − 0.2
  EXPECT_NEAR(WrappedPhaseDiff(-kPi + 0.05, kPi - 0.05), 0.1, kWrapTol);
  EXPECT_NEAR(WrappedPhaseDiff(0.3, -0.4), 0.7, kWrapTol);
  EXPECT_NEAR(WrappedPhaseDiff(kPi / 2, -kPi / 2), kPi, kWrapTol);
  EXPECT_NEAR(WrappedPhaseDiff(1.0, 1.0 + 4 * kPi), 0.0, 1e-9);

  // eq. (5) on hand-made responses: every filter differs by 0.2 rad across ±π.
  GaborResponses a, b;
  a.options.phase_exponent = 3.0;
  a.num_filters = b.num_filters = 16;
  a.phase.assign(16, static_cast<float>(kPi - 0.1));
  b.phase.assign(16, static_cast<float>(-kPi + 0.1));
  a.amplitude.assign(16, 10.f);
  b.amplitude.assign(16, 10.f);
  b.options = a.options;
  constexpr double kFloatPhaseTol = 1e-6;  // phases stored as float
  EXPECT_NEAR(GaborPhaseSimilarity(a, 0, b, 0), std::exp(-3.0 * 0.2), kFloatPhaseTol);
  // Half the filters 0.2 apart, half 1.0 apart: the mean is 0.6 (uniform weighting).
  for (int k = 8; k < 16; ++k) b.phase[k] = static_cast<float>(kPi - 1.1);
  EXPECT_NEAR(GaborPhaseSimilarity(a, 0, b, 0), std::exp(-3.0 * 0.6), kFloatPhaseTol);
  // Amplitude weighting: the 1.0-apart filters are 9× stronger → mean (8·0.2 + 72·1.0)/80.
  a.options.weighting = PhaseWeighting::kAmplitude;
  for (int k = 8; k < 16; ++k) a.amplitude[k] = b.amplitude[k] = 90.f;
  EXPECT_NEAR(GaborPhaseSimilarity(a, 0, b, 0), std::exp(-3.0 * (1.6 + 72.0) / 80.0),
              kFloatPhaseTol);
  // Below min_amplitude a filter is ignored; with none usable the similarity is that of
  // unrelated phases, exp(−β π/2).
  a.options.weighting = PhaseWeighting::kUniform;
  a.options.min_amplitude = 50.0;
  EXPECT_NEAR(GaborPhaseSimilarity(a, 0, b, 0), std::exp(-3.0 * 1.0), kFloatPhaseTol);
  a.options.min_amplitude = 100.0;
  EXPECT_NEAR(GaborPhaseSimilarity(a, 0, b, 0), std::exp(-3.0 * kPi / 2), kFloatPhaseTol);
}

TEST(GaborTest, FlatImageAndBorderMakeFiltersUnusable) {
  const GaborBank bank;
  const cv::Mat flat(120, 160, CV_8U, cv::Scalar(100));
  const GaborResponses r = bank.Compute(flat, {At(80, 60), At(3, 60)});
  const double beta = bank.options().phase_exponent;
  for (int k = 0; k < bank.num_filters(); ++k) {
    EXPECT_LT(r.amplitude_of(0)[k], bank.options().min_amplitude);  // ~0: no phase
    EXPECT_LT(r.amplitude_of(1)[k], 0.f);                           // window crosses the border
  }
  EXPECT_NEAR(GaborPhaseSimilarity(r, 0, r, 0), std::exp(-beta * kPi / 2), 1e-12);
  // Near the border only the small kernels fit: x = 8 fits λ = 4 and 6 (radius 5 and 7 px) but
  // not the half-resolution ones (radius 5 and 7 around x = 4 at half resolution).
  cv::Mat texture(120, 160, CV_8U);
  cv::randu(texture, 0, 255);
  const GaborResponses t = bank.Compute(texture, {At(8, 60)});
  for (int k = 0; k < bank.num_filters(); ++k) {
    const int w = k / bank.options().num_orientations;
    EXPECT_EQ(t.amplitude_of(0)[k] >= 0.f, (8 >> bank.level(w)) >= bank.radius(w))
        << "filter " << k;
  }
  EXPECT_EQ(bank.level(0), 0);
  EXPECT_EQ(bank.level(3), 1);
  EXPECT_TRUE(bank.Compute(texture, {}).phase.empty());
}

TEST(GaborTest, OptionsValidation) {
  GaborOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  EXPECT_EQ(o.num_filters(), 16);
  o.wavelengths_px = {2.0};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("wavelengths_px"), std::string::npos);
  o = GaborOptions();
  o.num_orientations = 0;
  EXPECT_FALSE(o.IsValid(&error));
  o = GaborOptions();
  o.phase_exponent = 0.0;
  EXPECT_FALSE(o.IsValid(&error));
  o = GaborOptions();
  o.half_res_min_wavelength_px = 4.0;
  EXPECT_FALSE(o.IsValid(&error));
  // Other orientation counts use more vector lanes; the phase law still holds.
  GaborOptions six;
  six.num_orientations = 6;
  six.wavelengths_px = {5.0};
  const GaborBank bank(six);
  for (int k = 0; k < 6; ++k) {
    const double theta = kPi * k / 6;
    const GaborResponses a = bank.Compute(Sinusoid(5.0, theta, 0.0), {At(80, 60)});
    const GaborResponses b = bank.Compute(Sinusoid(5.0, theta, 1.0), {At(80, 60)});
    EXPECT_NEAR(std::remainder(b.phase_of(0)[k] - a.phase_of(0)[k] - 2 * kPi / 5.0, 2 * kPi), 0.0,
                kPhaseTolRad);
  }
}

}  // namespace
}  // namespace vo
