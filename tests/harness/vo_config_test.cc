// Every field of vo::OdometryOptions can be written to vo_options.yaml and read back (so a run
// folder's file reproduces its result): the VO-config registry (harness/vo_config.cc) covers
// every field of every nested Options struct, grouped by the pipeline's stages; the keys of
// the layout before the stages are refused with their new names.
//
// C++ cannot list a struct's fields, so this test records each Options struct's size and
// the number of keys per group of vo_options.yaml. A field added to a struct changes its size and
// the test fails until the field is registered in harness/vo_config.cc (or listed as internal
// here, with the reason) and the recorded size and count are updated. (A small field that
// fits in a struct's tail padding leaves its size unchanged: the size is a guard, not a proof.)
#include "harness/vo_config.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <iterator>
#include <map>
#include <string>
#include <vector>

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

// An Options struct of vo/ whose fields the registry holds.
struct Recorded {
  const char* type;      // the Options struct
  size_t size;           // its sizeof now
  size_t recorded_size;  // its sizeof when its fields were last registered (x86-64, GCC 12)
};

TEST(VoConfigTest, EveryOptionFieldIsRegistered) {
  const YAML::Node yaml = YAML::Load(harness::VoConfigToYaml(vo::OdometryOptions()));
  std::map<std::string, int> counts;
  CountLeaves(yaml, "", &counts);
  const Recorded recorded[] = {
      {"OdometryOptions", sizeof(vo::OdometryOptions), 1840},
      {"FrontEndOptions", sizeof(vo::FrontEndOptions), 304},
      {"InitialOrientationOptions", sizeof(vo::InitialOrientationOptions), 192},
      {"TrackerOptions", sizeof(vo::TrackerOptions), 544},
      {"RecoveryOptions", sizeof(vo::RecoveryOptions), 312},
      {"MotionOptions", sizeof(vo::MotionOptions), 224},
      {"DetectorOptions", sizeof(vo::DetectorOptions), 128},
      {"HarrisOptions", sizeof(vo::HarrisOptions), 64},
      {"SiftOptions", sizeof(vo::SiftOptions), 40},
      {"DisparityOptions", sizeof(vo::DisparityOptions), 72},
      {"DepthSamplingOptions", sizeof(vo::DepthSamplingOptions), 32},
      {"MatcherOptions", sizeof(vo::MatcherOptions), 424},
      {"NccOptions", sizeof(vo::NccOptions), 16},
      {"GaborOptions", sizeof(vo::GaborOptions), 96},
      {"SvdMatcherOptions", sizeof(vo::SvdMatcherOptions), 128},
      {"NccMutualMatcherOptions", sizeof(vo::NccMutualMatcherOptions), 16},
      {"LucasKanadeMatcherOptions", sizeof(vo::LucasKanadeMatcherOptions), 48},
      {"KalmanMatcherOptions", sizeof(vo::KalmanMatcherOptions), 88},
      {"SiftRatioMatcherOptions", sizeof(vo::SiftRatioMatcherOptions), 24},
      {"RansacOptions", sizeof(vo::RansacOptions), 88},
      {"BundleAdjustmentOptions", sizeof(vo::BundleAdjustmentOptions), 80},
      {"BackEndOptions", sizeof(vo::BackEndOptions), 176},
      {"VehiclePlanarBaOptions", sizeof(vo::VehiclePlanarBaOptions), 32},
      {"FlatFloorOptions", sizeof(vo::FlatFloorOptions), 24},
      {"PlaneOrientationOptions", sizeof(vo::PlaneOrientationOptions), 80},
      {"PlaneRefinementOptions", sizeof(vo::PlaneRefinementOptions), 88},
      {"PriorMotionOptions", sizeof(vo::PriorMotionOptions), 64},
      {"ImageShiftOptions", sizeof(vo::ImageShiftOptions), 56},
      {"BridgeAlignmentOptions", sizeof(vo::BridgeAlignmentOptions), 32},
      {"DirectAlignmentOptions", sizeof(vo::DirectAlignmentOptions), 96},
      {"ImuOptions", sizeof(vo::ImuOptions), 80},
  };
  for (const Recorded& r : recorded)
    EXPECT_EQ(r.size, r.recorded_size)
        << "vo::" << r.type << " changed size: register its new field in harness/vo_config.cc "
        << "(Registry), count it below and update the recorded size here";
  // The keys per group of vo_options.yaml, by stage (docs/DESIGN.md, "VO options by stage"):
  // the groups' fields of the stages' structs (FrontEndOptions, ..., BackEndOptions),
  // BackEndOptions (`back_end`, field for field) and the nested Options structs
  // (PriorMotionOptions' vehicle fields under `vehicle`).
  const std::map<std::string, int> expected = {
      {"", 1},  // platform
      {"vehicle", 3},
      {"front_end", 10},
      {"front_end.detector", 6},
      {"front_end.detector.harris", 10},
      {"front_end.detector.sift", 5},
      {"front_end.disparity", 14},
      {"front_end.depth", 5},
      {"initial_orientation", 5},
      {"initial_orientation.planes", 9},
      {"initial_orientation.floor_refinement", 11},
      {"tracker", 8},
      {"tracker.matcher", 2},
      {"tracker.matcher.ncc", 2},
      {"tracker.matcher.gabor", 11},
      {"tracker.matcher.svd", 17},
      {"tracker.matcher.ncc_mutual", 2},
      {"tracker.matcher.lucas_kanade", 7},
      {"tracker.matcher.kalman", 11},
      {"tracker.matcher.sift_ratio", 3},
      {"tracker.image_shift", 8},
      {"motion", 6},
      {"motion.ransac", 16},
      {"motion.few_point", 11},
      {"recovery", 9},
      {"recovery.vehicle_bridge", 5},
      {"recovery.vehicle_direct", 14},
      {"recovery.free_direct", 14},
      {"back_end", 6},
      {"back_end.ba", 12},
      {"back_end.vehicle_planar", 4},
      {"back_end.flat_floor", 3},
      {"imu", 13},
  };
  EXPECT_EQ(counts, expected);
}

// Leaf keys (dotted) and their values as YAML text (a list in flow style).
void Leaves(const YAML::Node& node, const std::string& prefix,
            std::map<std::string, std::string>* leaves) {
  for (const auto& kv : node) {
    const std::string key = prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar();
    if (kv.second.IsMap()) {
      Leaves(kv.second, key, leaves);
    } else {
      YAML::Emitter e;
      e << YAML::Flow << kv.second;
      (*leaves)[key] = e.c_str();
    }
  }
}

// The file vobench wrote before the stages (tests/harness/data/vo_options_before_stages.yaml):
// every one of its keys is refused, each names its new key (or the constant it became), and the
// file with its keys renamed so is read back to the same values, every new key given once.
TEST(VoConfigTest, EveryOldKeyIsRefusedAndItsNewKeyHoldsTheSameValue) {
  const std::string path =
      std::string(VOBENCH_SOURCE_DIR) + "/tests/harness/data/vo_options_before_stages.yaml";
  std::map<std::string, std::string> old_leaves;
  Leaves(YAML::LoadFile(path), "", &old_leaves);
  ASSERT_EQ(old_leaves.size(), 239u);

  std::string error;
  vo::OdometryOptions o;
  EXPECT_FALSE(harness::LoadVoConfig(path, &o, &error));
  EXPECT_NE(error.find("vo_options_before_stages.yaml:4: key 'detector': renamed"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("write `front_end.detector`"), std::string::npos) << error;

  std::string renamed_text;
  std::map<std::string, std::string> expected;
  std::vector<std::string> constants;
  for (const auto& [key, value] : old_leaves) {
    if (key == "platform") {  // the one key kept
      renamed_text += key + ": " + value + "\n";
      expected[key] = value;
      continue;
    }
    std::string constant;
    const std::string renamed = harness::RenamedVoKey(key, &constant);
    // Each old key alone is refused, with the new key's name.
    vo::OdometryOptions one;
    std::string one_error;
    EXPECT_FALSE(harness::ParseVoConfig(key + ": " + value + "\n", "one.yaml", &one, &one_error))
        << key;
    if (renamed.empty()) {
      ASSERT_FALSE(constant.empty()) << key << " has neither a new key nor a constant";
      constants.push_back(key + " -> " + constant);
      EXPECT_NE(one_error.find(constant), std::string::npos) << one_error;
      continue;
    }
    EXPECT_NE(one_error.find("one.yaml:1: key '" + key + "': renamed"), std::string::npos)
        << one_error;
    EXPECT_NE(one_error.find("`" + renamed + "`"), std::string::npos) << one_error;
    EXPECT_EQ(expected.count(renamed), 0u) << renamed << " given twice";
    renamed_text += renamed + ": " + value + "\n";
    expected[renamed] = value;
  }
  EXPECT_EQ(constants, (std::vector<std::string>{
                           "ba.min_depth_m -> vo::BundleAdjustmentOptions::kMinDepthM",
                           "ransac.min_depth_m -> vo::RansacOptions::kMinDepthM",
                           "tracking.few_point.min_depth_m -> vo::PriorMotionOptions::kMinDepthM",
                       }));
  vo::OdometryOptions read;
  ASSERT_TRUE(harness::ParseVoConfig(renamed_text, "renamed.yaml", &read, &error)) << error;
  std::map<std::string, std::string> written;
  Leaves(YAML::Load(harness::VoConfigToYaml(read)), "", &written);
  // The imu group and recovery.free_direct (issue #35) came after the earlier layout: the file
  // has none of their keys.
  for (auto it = written.begin(); it != written.end();) {
    const bool later =
        it->first.rfind("imu.", 0) == 0 || it->first.rfind("recovery.free_direct.", 0) == 0;
    it = later ? written.erase(it) : std::next(it);
  }
  EXPECT_EQ(written, expected);  // every new key once, with the old key's value
}

// A whole old group (`tracking:`) is refused at its first key's line; a nested old group
// (`matcher:`) at the group; a new key is read.
TEST(VoConfigTest, OldGroupsAreRefusedAtTheirLine) {
  vo::OdometryOptions o;
  std::string error;
  EXPECT_FALSE(harness::ParseVoConfig("platform: free\ntracking:\n  few_point_motion: true\n",
                                      "v.yaml", &o, &error));
  EXPECT_EQ(error,
            "v.yaml:3: key 'tracking.few_point_motion': renamed: the options are grouped by the "
            "pipeline's stages; write `motion.few_point.enabled` (docs/DESIGN.md, \"VO options by "
            "stage\")");
  EXPECT_FALSE(harness::ParseVoConfig("matcher:\n  type: ncc_mutual\n", "v.yaml", &o, &error));
  EXPECT_NE(error.find("v.yaml:1: key 'matcher': renamed"), std::string::npos) << error;
  EXPECT_NE(error.find("`tracker.matcher`"), std::string::npos) << error;
  EXPECT_FALSE(harness::ParseVoConfig("ba_window_frames: 3\n", "v.yaml", &o, &error));
  EXPECT_NE(error.find("`back_end.window_frames`"), std::string::npos) << error;
  ASSERT_TRUE(harness::ParseVoConfig(
      "tracker:\n  matcher: {type: ncc_mutual}\nback_end: {window_frames: 3}\n"
      "motion.few_point.enabled: true\n",
      "v.yaml", &o, &error))
      << error;
  EXPECT_EQ(o.tracker.matcher.type, vo::MatcherType::kNccMutual);
  EXPECT_EQ(o.back_end.window_frames, 3);
  EXPECT_TRUE(o.motion.few_point_motion);
  EXPECT_EQ(harness::RenamedVoKey("front_end.detector.type"), "");  // a new key is no old one
  EXPECT_EQ(harness::RenamedVoKey("disparity_mode"), "front_end.disparity_mode");
  EXPECT_EQ(harness::RenamedVoKey("disparity.block_size"), "front_end.disparity.block_size");
  EXPECT_EQ(harness::RenamedVoKey("tracking.few_point.axle_behind_camera_m"),
            "vehicle.axle_behind_camera_m");
}

}  // namespace
