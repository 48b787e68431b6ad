// The sequence cache (harness/sequence_cache.h): the frames read back equal the simulated ones
// bit for bit, a damaged or partial entry is never used, runs at once wait on one simulation,
// and a run on the cache writes the run folder a simulating run writes.
#include "harness/sequence_cache.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "harness/sim_adapter.h"
#include "tests/harness/cli_test_util.h"
#include "tests/sim/sim_test_util.h"

namespace {

namespace fs = std::filesystem;
using harness::DatasetFrame;
using harness::StereoSequence;
using vobench_test::ReadAll;
using vobench_test::RunVobench;
using vobench_test::TempDir;
using vobench_test::WriteText;

constexpr int kFrames = 5;

sim::Scenario LHallway() {
  sim::Scenario scenario;
  std::string error;
  EXPECT_TRUE(harness::ResolveScenario("l_hallway", &scenario, &error)) << error;
  return scenario;
}

// Bit-for-bit equality of plain values (doubles compared by their bits, not by ==).
template <typename T>
bool SameBits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}
bool SameBits(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return std::memcmp(a.data(), b.data(), 16 * sizeof(double)) == 0;
}
bool SameBits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}
bool SameImage(const cv::Mat& a, const cv::Mat& b) {
  if (a.type() != b.type() || a.size() != b.size()) return false;
  for (int r = 0; r < a.rows; ++r)
    if (std::memcmp(a.ptr(r), b.ptr(r), a.cols * a.elemSize()) != 0) return false;
  return true;
}

void ExpectSameFrame(const DatasetFrame& a, const DatasetFrame& b, int index) {
  SCOPED_TRACE("frame " + std::to_string(index));
  EXPECT_TRUE(SameBits(a.time_s, b.time_s));
  EXPECT_EQ(a.has_gt, b.has_gt);
  EXPECT_TRUE(SameBits(a.T_world_cam0, b.T_world_cam0));
  EXPECT_FALSE(a.left.empty());
  EXPECT_TRUE(SameImage(a.left, b.left));
  EXPECT_TRUE(SameImage(a.right, b.right));
  EXPECT_FALSE(a.depth_m.empty());
  EXPECT_TRUE(SameImage(a.depth_m, b.depth_m));
  ASSERT_EQ(a.imu.size(), b.imu.size());
  EXPECT_FALSE(a.imu.empty());
  for (size_t k = 0; k < a.imu.size(); ++k) {
    const sim::ImuSample &s = a.imu[k], &t = b.imu[k];
    EXPECT_TRUE(SameBits(s.time_s, t.time_s) && SameBits(s.gyro_radps, t.gyro_radps) &&
                SameBits(s.accel_mps2, t.accel_mps2) && s.has_gt == t.has_gt &&
                SameBits(s.gyro_true_radps, t.gyro_true_radps) &&
                SameBits(s.accel_true_mps2, t.accel_true_mps2) &&
                SameBits(s.gyro_bias_radps, t.gyro_bias_radps) &&
                SameBits(s.accel_bias_mps2, t.accel_bias_mps2) &&
                SameBits(s.T_world_imu, t.T_world_imu) && SameBits(s.v_world_mps, t.v_world_mps))
        << "IMU sample " << k;
  }
}

// Every frame of `cached` equals the one simulated for `scenario` (kFrames of them).
void ExpectSameAsSimulated(const sim::Scenario& scenario, StereoSequence& cached) {
  StereoSequence simulated;
  std::string error;
  ASSERT_TRUE(harness::OpenScenarioSequence(scenario, &simulated, &error)) << error;
  EXPECT_EQ(cached.name, simulated.name);
  EXPECT_EQ(cached.scenario_yaml, simulated.scenario_yaml);
  EXPECT_EQ(cached.outline_scene, simulated.outline_scene);
  EXPECT_TRUE(SameBits(cached.axle_behind_camera_m, simulated.axle_behind_camera_m));
  EXPECT_TRUE(SameBits(cached.camera_pitch_deg, simulated.camera_pitch_deg));
  EXPECT_TRUE(SameBits(cached.T_imu_cam0, simulated.T_imu_cam0));
  const vo::StereoCamera &c = cached.camera, &s = simulated.camera;
  EXPECT_TRUE(c.width == s.width && c.height == s.height && SameBits(c.fx_px, s.fx_px) &&
              SameBits(c.fy_px, s.fy_px) && SameBits(c.cx_px, s.cx_px) &&
              SameBits(c.cy_px, s.cy_px) && SameBits(c.baseline_m, s.baseline_m));
  EXPECT_EQ(cached.expected_frames, kFrames);
  DatasetFrame a, b;
  for (int i = 0; i < kFrames; ++i) {
    ASSERT_TRUE(cached.next(&a, &error)) << error;
    ASSERT_TRUE(simulated.next(&b, &error)) << error;
    ExpectSameFrame(a, b, i);
  }
  EXPECT_FALSE(cached.next(&a, &error));  // the entry holds max_frames frames
  EXPECT_EQ(error, "");
  // What the robot did (the follower's report) as the simulation after the same frames.
  ASSERT_TRUE(cached.navigation && simulated.navigation);
  const sim::NavigationReport n = cached.navigation(), m = simulated.navigation();
  EXPECT_EQ(n.mode, m.mode);
  EXPECT_EQ(n.reached_goal, m.reached_goal);
  EXPECT_TRUE(SameBits(n.end_error_m, m.end_error_m) &&
              SameBits(n.max_waypoint_error_m, m.max_waypoint_error_m) &&
              SameBits(n.wall_contact_s, m.wall_contact_s));
  EXPECT_EQ(n.wall_contacts, m.wall_contacts);
  ASSERT_EQ(n.frames.size(), m.frames.size());
  for (size_t k = 0; k < n.frames.size(); ++k)
    EXPECT_TRUE(SameBits(n.frames[k].time_s, m.frames[k].time_s) &&
                SameBits(n.frames[k].truth.position, m.frames[k].truth.position) &&
                SameBits(n.frames[k].believed.yaw_rad, m.frames[k].believed.yaw_rad))
        << "navigation frame " << k;
}

TEST(SequenceCacheTest, TheCachedFramesEqualTheSimulatedOnesBitForBit) {
  TempDir dir("seqcache_equal");
  const sim::Scenario scenario = LHallway();
  const std::string entry = dir / "entry";
  std::string error;
  ASSERT_TRUE(harness::WriteSequenceCache(scenario, kFrames, entry, false, &error)) << error;
  EXPECT_TRUE(harness::HasFolderMarker(entry, "sequence"));
  std::string why;
  EXPECT_TRUE(harness::IsUsableSequenceCache(scenario, kFrames, entry, &why)) << why;
  StereoSequence cached;
  ASSERT_TRUE(harness::OpenCachedSequence(scenario, kFrames, entry, &cached, &error)) << error;
  ExpectSameAsSimulated(scenario, cached);

  // The entry is of one scenario and max_frames: another seed or frame count is not it.
  sim::Scenario other = scenario;
  other.seed += 1;
  EXPECT_FALSE(harness::IsUsableSequenceCache(other, kFrames, entry, &why));
  EXPECT_NE(why.find("another scenario or max_frames"), std::string::npos) << why;
  EXPECT_FALSE(harness::IsUsableSequenceCache(scenario, kFrames + 1, entry, &why));
  EXPECT_NE(harness::SequenceCacheKey(scenario, kFrames),
            harness::SequenceCacheKey(other, kFrames));
  EXPECT_NE(harness::SequenceCacheKey(scenario, kFrames),
            harness::SequenceCacheKey(scenario, kFrames + 1));
  // The scenario's name is not part of it (a suite names each run's scenario after the run).
  other = scenario;
  other.name = "l_corner__free__s1__k2";
  EXPECT_EQ(harness::SequenceCacheKey(scenario, kFrames),
            harness::SequenceCacheKey(other, kFrames));
  EXPECT_TRUE(harness::IsUsableSequenceCache(other, kFrames, entry, &why)) << why;
}

// The scenario names its scene by path: the key follows the scene's files by content, the MJCF
// and what it includes, so an entry kept across calls never gives an edited scene's old frames.
TEST(SequenceCacheTest, TheKeyFollowsTheSceneFilesContent) {
  TempDir dir("seqcache_scene");
  const std::string scene = vobench_test::WriteScene(dir, "");
  const sim::Scenario scenario = vobench_test::MakeScenario(scene);
  const std::string before = harness::SequenceCacheKey(scenario, kFrames);
  EXPECT_EQ(harness::SequenceCacheKey(scenario, kFrames), before);  // the same files, one key
  const std::string text = ReadAll(scene);
  WriteText(scene, text + "<!-- edited -->\n");
  const std::string edited_scene = harness::SequenceCacheKey(scenario, kFrames);
  EXPECT_NE(edited_scene, before);
  WriteText(scene, text);
  EXPECT_EQ(harness::SequenceCacheKey(scenario, kFrames), before);
  const std::string robot = dir / "robot_p2dx.xml";
  WriteText(robot, ReadAll(robot) + "<!-- edited -->\n");  // the included robot
  EXPECT_NE(harness::SequenceCacheKey(scenario, kFrames), before);
}

TEST(SequenceCacheTest, ADamagedOrPartialEntryIsNotUsed) {
  TempDir dir("seqcache_damaged");
  const sim::Scenario scenario = LHallway();
  const std::string cache = dir / "cache";
  const fs::path entry = fs::path(cache) / harness::SequenceCacheKey(scenario, kFrames);
  std::string error, why;
  StereoSequence sequence;
  // A work folder left by an interrupted writer is not the entry: it is simulated.
  fs::create_directories(entry.string() + ".partial-1-AbC123");
  ASSERT_TRUE(
      harness::OpenSharedScenarioSequence(scenario, kFrames, cache, false, &sequence, &error))
      << error;
  ASSERT_TRUE(harness::IsUsableSequenceCache(scenario, kFrames, entry.string(), &why)) << why;
  const std::string good_frames = ReadAll((entry / "frames.bin").string());

  // A truncated frames.bin: not usable (named), and simulated again by the next run.
  fs::resize_file(entry / "frames.bin", good_frames.size() / 2);
  EXPECT_FALSE(harness::IsUsableSequenceCache(scenario, kFrames, entry.string(), &why));
  EXPECT_NE(why.find("frames.bin has"), std::string::npos) << why;
  ASSERT_TRUE(
      harness::OpenSharedScenarioSequence(scenario, kFrames, cache, false, &sequence, &error))
      << error;
  EXPECT_EQ(ReadAll((entry / "frames.bin").string()), good_frames);
  ExpectSameAsSimulated(scenario, sequence);

  // A missing or unreadable index, or no marker: not usable either.
  WriteText((entry / "sequence.json").string(), "{\"format\": 1");
  EXPECT_FALSE(harness::IsUsableSequenceCache(scenario, kFrames, entry.string(), &why));
  EXPECT_NE(why.find("sequence.json"), std::string::npos) << why;
  fs::remove(entry / ".vobench.json");
  EXPECT_FALSE(harness::IsUsableSequenceCache(scenario, kFrames, entry.string(), &why));
  EXPECT_NE(why.find("no marker"), std::string::npos) << why;
  // ... and a folder there that vobench did not write is never replaced: a clear error.
  EXPECT_FALSE(
      harness::OpenSharedScenarioSequence(scenario, kFrames, cache, false, &sequence, &error));
  EXPECT_NE(error.find("was not written by vobench"), std::string::npos) << error;
  fs::remove_all(entry);

  // A frame changed in place (same size): the index looks fine, reading that frame fails.
  ASSERT_TRUE(
      harness::OpenSharedScenarioSequence(scenario, kFrames, cache, false, &sequence, &error))
      << error;
  {
    std::fstream f(entry / "frames.bin", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(good_frames.size() - 1000));
    f.put(static_cast<char>(good_frames[good_frames.size() - 1000] ^ 1));
  }
  ASSERT_TRUE(harness::OpenCachedSequence(scenario, kFrames, entry.string(), &sequence, &error))
      << error;
  DatasetFrame frame;
  for (int i = 0; i < kFrames - 1; ++i) ASSERT_TRUE(sequence.next(&frame, &error)) << error;
  EXPECT_FALSE(sequence.next(&frame, &error));
  EXPECT_NE(error.find("frames.bin: frame 4 does not match its hash"), std::string::npos) << error;
}

// Two `vobench run`s of one scenario at once with one --sequence-cache: one simulates, the
// other waits for it and reads; both write the run folder a run without the cache writes.
TEST(SequenceCacheTest, ConcurrentRunsWaitOnOneSimulationAndEqualASimulatingRun) {
  TempDir dir("seqcache_concurrent");
  const std::string cache = dir / "cache";
  std::vector<pid_t> pids;
  for (const char* stride : {"1", "2"})
    pids.push_back(vobench_test::StartVobench(
        {"run", "l_hallway", "--max-frames", "8", "--stride", stride, "--no-plots", "-q",
         "--sequence-cache", cache, "--out", dir / (std::string("cached_k") + stride)},
        dir / (std::string("k") + stride + ".log")));
  for (pid_t pid : pids) {
    ASSERT_GT(pid, 0);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  const std::string log1 = ReadAll(dir / "k1.log"), log2 = ReadAll(dir / "k2.log");
  const auto simulated = [](const std::string& log) {
    return log.find(": simulating") != std::string::npos;
  };
  EXPECT_TRUE(simulated(log1) != simulated(log2)) << log1 << "\n---\n" << log2;
  EXPECT_NE((log1 + log2).find("simulated before, reading it"), std::string::npos);
  for (const char* stride : {"1", "2"}) {
    const std::string plain = dir / (std::string("plain_k") + stride);
    const auto r = RunVobench(std::string("run l_hallway --max-frames 8 --no-plots -q --stride ") +
                              stride + " --out " + plain);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const fs::path cached = dir / (std::string("cached_k") + stride);
    for (const char* f :
         {"trajectory_world_tum.txt", "trajectory_kitti.txt", "groundtruth_world_tum.txt",
          "estimate_in_gt_world_tum.txt", "scenario.yaml", "vo_options.yaml"})
      EXPECT_EQ(ReadAll((cached / f).string()), ReadAll(fs::path(plain) / f)) << stride << f;
    // metrics.json equal but for the timing figures.
    auto metrics = [](const fs::path& run) {
      nlohmann::json j = nlohmann::json::parse(ReadAll((run / "metrics.json").string()));
      for (const char* k : {"vo_ms_median", "vo_ms_p95", "stage_ms_median"}) j.erase(k);
      return j;
    };
    EXPECT_EQ(metrics(cached), metrics(plain)) << stride;
  }
  // A closed-loop run's frames depend on its VO: it simulates in the loop, nothing cached.
  const std::string closed = dir / "closed";
  const auto c = RunVobench(
      "run " + std::string(VOBENCH_SOURCE_DIR) + "/scenes/l_hallway_closed_loop.yaml" +
      " --max-frames 5 --no-plots -q --sequence-cache " + (dir / "cache2") + " --out " + closed);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  EXPECT_FALSE(fs::exists(dir / "cache2") && !fs::is_empty(dir / "cache2"));
  EXPECT_EQ(nlohmann::json::parse(ReadAll(closed + "/metrics.json"))["navigation"]["mode"], "vo");
  // Not for a dataset folder.
  const auto r = RunVobench("run --dataset " + (dir / "cached_k1") + " --sequence-cache " + cache);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--sequence-cache: only for a simulated scenario"), std::string::npos)
      << r.output;
}

}  // namespace
