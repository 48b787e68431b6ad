// Every field of vo::OdometryOptions can be written to vo_options.yaml and read back (so a run
// folder's file reproduces its result): the VO-config registry (harness/vo_config.cc) covers
// every field of every nested Options struct.
//
// C++ cannot list a struct's fields, so this test records, per Options struct, its size and
// the number of its fields the registry holds. A field added to a struct changes its size and
// the test fails until the field is registered in harness/vo_config.cc (or listed as internal
// here, with the reason) and the recorded size and count are updated. (A small field that
// fits in a struct's tail padding leaves its size unchanged: the size is a guard, not a proof.)
#include "harness/vo_config.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <map>
#include <string>

#include "vo/odometry.h"

namespace {

// Leaf keys (scalars and lists) under `node`, counted by their parent's dotted path.
void CountLeaves(const YAML::Node& node, const std::string& prefix,
                 std::map<std::string, int>* counts) {
  for (const auto& kv : node) {
    if (kv.second.IsMap()) {
      const std::string key = prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar();
      CountLeaves(kv.second, key, counts);
    } else {
      ++(*counts)[prefix];
    }
  }
}

struct Covered {
  const char* group;      // dotted path of the struct in vo_options.yaml ("" = top level)
  const char* type;       // the Options struct
  size_t size;            // its sizeof now
  size_t recorded_size;   // its sizeof when its fields were last registered (x86-64, GCC 12)
  int registered_fields;  // scalar fields the registry must hold for it
};

TEST(VoConfigTest, EveryOptionFieldIsRegistered) {
  const YAML::Node yaml = YAML::Load(harness::VoConfigToYaml(vo::OdometryOptions()));
  std::map<std::string, int> counts;
  CountLeaves(yaml, "", &counts);
  const Covered covered[] = {
      {"", "OdometryOptions", sizeof(vo::OdometryOptions), 1680, 25},
      {"detector", "DetectorOptions", sizeof(vo::DetectorOptions), 128, 6},
      {"detector.harris", "HarrisOptions", sizeof(vo::HarrisOptions), 64, 10},
      {"detector.sift", "SiftOptions", sizeof(vo::SiftOptions), 40, 5},
      {"disparity", "DisparityOptions", sizeof(vo::DisparityOptions), 72, 14},
      {"depth", "DepthSamplingOptions", sizeof(vo::DepthSamplingOptions), 32, 5},
      {"matcher", "MatcherOptions", sizeof(vo::MatcherOptions), 424, 2},
      {"matcher.ncc", "NccOptions", sizeof(vo::NccOptions), 16, 2},
      {"matcher.gabor", "GaborOptions", sizeof(vo::GaborOptions), 96, 11},
      {"matcher.svd", "SvdMatcherOptions", sizeof(vo::SvdMatcherOptions), 128, 17},
      {"matcher.ncc_mutual", "NccMutualMatcherOptions", sizeof(vo::NccMutualMatcherOptions), 16, 2},
      {"matcher.lucas_kanade", "LucasKanadeMatcherOptions", sizeof(vo::LucasKanadeMatcherOptions),
       48, 7},
      {"matcher.kalman", "KalmanMatcherOptions", sizeof(vo::KalmanMatcherOptions), 88, 11},
      {"matcher.sift_ratio", "SiftRatioMatcherOptions", sizeof(vo::SiftRatioMatcherOptions), 24, 3},
      {"ransac", "RansacOptions", sizeof(vo::RansacOptions), 96, 17},
      {"ba", "BundleAdjustmentOptions", sizeof(vo::BundleAdjustmentOptions), 88, 13},
      {"orientation", "PlaneOrientationOptions", sizeof(vo::PlaneOrientationOptions), 80, 9},
      {"floor_refinement", "PlaneRefinementOptions", sizeof(vo::PlaneRefinementOptions), 88, 11},
      {"tracking", "RobustTrackingOptions", sizeof(vo::RobustTrackingOptions), 528, 34},
      {"tracking.few_point", "PriorMotionOptions", sizeof(vo::PriorMotionOptions), 80, 10},
      {"tracking.image_shift", "ImageShiftOptions", sizeof(vo::ImageShiftOptions), 56, 8},
      {"tracking.vehicle_bridge", "BridgeAlignmentOptions", sizeof(vo::BridgeAlignmentOptions), 32,
       4},
      {"tracking.vehicle_direct", "DirectAlignmentOptions", sizeof(vo::DirectAlignmentOptions), 96,
       13},
  };
  int total = 0;
  for (const Covered& c : covered) {
    EXPECT_EQ(c.size, c.recorded_size)
        << "vo::" << c.type << " changed size: register its new field in harness/vo_config.cc "
        << "(Registry) and update the recorded size and field count here";
    EXPECT_EQ(counts[c.group], c.registered_fields)
        << "registered keys under '" << c.group << "' (" << c.type << ")";
    total += c.registered_fields;
  }
  // No key outside these groups.
  int all = 0;
  for (const auto& [group, n] : counts) all += n;
  EXPECT_EQ(all, total);
}

}  // namespace
