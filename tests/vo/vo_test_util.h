// Helpers shared by the vo/ tests: the synthetic stereo head, Gaussian noise and the check of a
// stage's options (ExpectOptionsRefuseBadFields).
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "vo/camera.h"
#include "vo/ransac.h"
#include "vo/types.h"

namespace vo {
namespace test {

// The tests' rectified stereo head: 320x240, f = 300 px, principal point at the centre,
// baseline 0.12 m.
inline StereoCamera TestCamera() {
  StereoCamera cam;
  cam.width = 320;
  cam.height = 240;
  cam.fx_px = cam.fy_px = 300.0;
  cam.cx_px = 159.5;
  cam.cy_px = 119.5;
  cam.baseline_m = 0.12;
  return cam;
}

// The simulator's hallway rig (docs/DESIGN.md / the harness): 320x240, fx ≈ 230 px, 0.09 m.
inline StereoCamera HallwayCamera() {
  StereoCamera cam;
  cam.width = 320;
  cam.height = 240;
  cam.fx_px = cam.fy_px = 230.0;
  cam.cx_px = 159.5;
  cam.cy_px = 119.5;
  cam.baseline_m = 0.09;
  return cam;
}

// The pose [R | t].
inline Eigen::Isometry3d MakePose(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

// A standard normal sample (Box-Muller) from the seeded generator.
inline double Normal(SplitMix64* rng) {
  const double u1 = 1.0 - rng->Uniform();
  const double u2 = rng->Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// A feature of `camera` at p (camera frame, metres): its pixel, exact disparity and point.
inline Feature FeatureAt(const StereoCamera& camera, const Eigen::Vector3d& p) {
  Feature f;
  EXPECT_TRUE(camera.ProjectLeft(p, &f.uv_px));
  f.disparity_px = camera.DisparityFromDepth(p.z());
  f.p_cam0 = p;
  return f;
}

// A window's sequence (sliding_window_test, back_end_test): camera i 0.1 m forward per frame
// along the optical axis.
inline Eigen::Isometry3d ForwardPose(int i) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.0, 0.0, 0.1 * i);
  return T;
}

// Exact stereo features of that sequence's frame i: a fixed cloud of 60 points 3-8 m ahead,
// seen by every frame (feature k = point k).
inline std::vector<Feature> ForwardFrameFeatures(int i, const StereoCamera& camera) {
  std::vector<Feature> features;
  SplitMix64 rng(3);
  for (int k = 0; k < 60; ++k) {
    const Eigen::Vector3d p_world(-1.5 + 3.0 * rng.Uniform(), -1.0 + 2.0 * rng.Uniform(),
                                  3.0 + 5.0 * rng.Uniform());
    features.push_back(FeatureAt(camera, ForwardPose(i).inverse() * p_world));
  }
  return features;
}

// Matches k -> k for n features.
inline std::vector<Match> OneToOneMatches(size_t n) {
  std::vector<Match> matches;
  for (size_t k = 0; k < n; ++k) {
    Match m;
    m.prev = static_cast<int>(k);
    m.curr = static_cast<int>(k);
    matches.push_back(m);
  }
  return matches;
}

// One bad value of an options struct's field: `change` sets it, `field` is what the refusal's
// message must name.
template <typename Options>
struct BadField {
  std::string field;
  std::function<void(Options*)> change;
};

// A stage's options (FrontEndOptions, TrackerOptions, ...): the defaults are valid, and each of
// `bad` applied to the defaults is refused (IsValid false) with a message that names its field.
template <typename Options>
void ExpectOptionsRefuseBadFields(const std::vector<BadField<Options>>& bad) {
  std::string error;
  EXPECT_TRUE(Options().IsValid(&error)) << error;
  EXPECT_TRUE(Options().IsValid(nullptr));
  for (const BadField<Options>& b : bad) {
    Options options;
    b.change(&options);
    error.clear();
    EXPECT_FALSE(options.IsValid(&error)) << b.field;
    EXPECT_FALSE(options.IsValid(nullptr)) << b.field;
    EXPECT_THAT(error, ::testing::HasSubstr(b.field));
  }
}

}  // namespace test
}  // namespace vo
