#include "harness/pipeline.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "harness/dataset/rectification.h"
#include "harness/interrupt.h"
#include "harness/progress.h"
#include "harness/render.h"
#include "harness/sim_adapter.h"
#include "sim/simulator.h"

namespace harness {

bool OpenScenarioSequence(const sim::Scenario& scenario, StereoSequence* sequence,
                          std::string* error) {
  std::shared_ptr<sim::Simulator> simulator = sim::Simulator::Create(scenario, error);
  if (!simulator) return false;
  DescribeScenarioSequence(scenario, simulator->calibration(), simulator->EstimatedFrames(),
                           sequence);
  sequence->next = [simulator, f = sim::StereoFrame()](DatasetFrame* frame,
                                                       std::string* err) mutable {
    if (!simulator->Next(&f, err)) return false;
    *frame = ToDatasetFrame(f);
    return true;
  };
  sequence->navigation = [simulator] { return simulator->navigation(); };
  if (scenario.navigation == "vo") {
    // The follower steers on the VO: each measured estimate, mapped into the world from the
    // belief at the VO's first frame (the known start), fixes the belief; a lost frame does not.
    sequence->feedback = [simulator,
                          fixes = sim::NavigationFixes(simulator->calibration().T_body_cam0,
                                                       scenario.robot.wheel_radius_m)](
                             const vo::OdometryResult& result) mutable {
      if (vo::IsLostFrame(result)) return;
      simulator->FixAtLastFrame(fixes.Fix(result.T_world_cam0, simulator->BeliefAtLastFrame()));
    };
  }
  return RectifyScenarioSequence(scenario, simulator->calibration(), sequence, error);
}

bool RectifyScenarioSequence(const sim::Scenario& scenario,
                             const sim::StereoCalibration& calibration, StereoSequence* sequence,
                             std::string* error) {
  auto rectification = std::make_shared<StereoRectification>();
  if (!ExportedRectification(scenario, calibration, rectification.get(), error)) return false;
  if (rectification->IsIdentity()) return true;
  Eigen::Isometry3d T_cam0_rect0 = Eigen::Isometry3d::Identity();
  T_cam0_rect0.linear() = rectification->R_cam0_rect0;
  sequence->camera = rectification->camera;
  sequence->T_imu_cam0 = sequence->T_imu_cam0 * T_cam0_rect0;
  sequence->next = [next = sequence->next, rectification](DatasetFrame* frame, std::string* err) {
    if (!next(frame, err)) return false;
    RectifyFrame(*rectification, frame);
    return true;
  };
  if (sequence->feedback)  // the follower's fixes are of the raw left camera
    sequence->feedback = [feedback = sequence->feedback,
                          T_rect0_cam0 = T_cam0_rect0.inverse()](const vo::OdometryResult& r) {
      vo::OdometryResult raw = r;
      raw.T_world_cam0 = r.T_world_cam0 * T_rect0_cam0;
      feedback(raw);
    };
  return true;
}

std::string ClosedLoopProblem(const sim::Scenario& scenario, const std::string& command) {
  if (scenario.navigation != "vo") return "";
  return (scenario.source_path.empty() ? scenario.name : scenario.source_path) +
         ": navigation: vo steers the robot on the VO frame by frame; `" + command +
         "` simulates without a VO in the loop (use `vobench run`, or navigation: ground_truth)";
}

void DescribeScenarioSequence(const sim::Scenario& scenario,
                              const sim::StereoCalibration& calibration, int expected_frames,
                              StereoSequence* sequence) {
  sequence->name = scenario.name;
  sequence->camera = ExportedStereoCamera(scenario, calibration);
  sequence->expected_frames = expected_frames;
  sequence->scenario_yaml = sim::ScenarioToYaml(scenario);
  sequence->outline_scene = scenario.scene_path;
  sequence->axle_behind_camera_m = scenario.camera.forward_m;
  sequence->camera_pitch_deg = scenario.camera.pitch_deg;
  sequence->has_imu = true;
  sequence->imu = scenario.imu;
  sequence->T_imu_cam0 = CameraInImuFrame(calibration.T_body_cam0, calibration.T_body_imu);
  sequence->imu_extrinsics_known = true;
}

bool ReadAllFrames(const FrameSource& source, int max_frames, int expected_frames,
                   const std::string& label, bool progress, const std::string& out,
                   std::vector<DatasetFrame>* frames, std::string* error) {
  frames->clear();
  if (max_frames > 0 && (expected_frames <= 0 || expected_frames > max_frames))
    expected_frames = max_frames;
  Progress bar(label, expected_frames, progress);
  DatasetFrame frame;
  while ((max_frames <= 0 || static_cast<int>(frames->size()) < max_frames) &&
         source(&frame, error)) {
    frames->push_back(frame);
    bar.Update(static_cast<int>(frames->size()));
    if (InterruptSignal() != 0) {
      *error = InterruptedMessage(static_cast<int>(frames->size()), expected_frames, "frames", out);
      return false;
    }
  }
  if (!error->empty()) return false;
  bar.Finish(static_cast<int>(frames->size()));
  return true;
}

FrameSource FramesInMemory(const std::vector<DatasetFrame>& frames) {
  return [&frames, next = size_t{0}](DatasetFrame* frame, std::string*) mutable {
    if (next >= frames.size()) return false;
    *frame = frames[next++];  // cv::Mat copies share the pixels
    return true;
  };
}

bool RunFramesOptions::IsValid(std::string* error) const {
  if (frame_stride >= 1) return true;
  *error = "frame stride must be >= 1, got " + std::to_string(frame_stride);
  return false;
}

bool RunFrames(const std::string& name, const FrameSource& source, vo::StereoOdometry& odometry,
               const RunFramesOptions& options, RunRecords* records, std::string* error) {
  if (!options.IsValid(error)) return false;
  RunRecords& r = *records;
  r = RunRecords();
  r.name = name;
  r.frame_stride = options.frame_stride;
  const int stride = options.frame_stride;
  int expected_frames = options.expected_frames;
  if (options.max_frames > 0 && (expected_frames <= 0 || expected_frames > options.max_frames))
    expected_frames = options.max_frames;
  const int expected_vo_frames = (expected_frames + stride - 1) / stride;
  Progress progress("vo " + name, expected_vo_frames, options.progress);
  // Matcher statistics where the ground truth allows (frames with depth and pose): the VO's
  // matches to its reference frame (the last frame that was not lost) checked against them.
  const MatchEvalOptions match_eval_options;
  GroundTruthFrame reference_gt;
  bool have_reference_gt = false;
  DatasetFrame frame;
  int source_frames = 0;
  error->clear();
  std::vector<vo::GyroSample> gyro;
  while ((options.max_frames <= 0 || source_frames < options.max_frames) && source(&frame, error)) {
    // The gyro's samples of every source frame, the skipped ones' too (ignored by a VO without
    // the gyro: StereoOdometry::SetGyro).
    if (!frame.imu.empty()) {
      gyro.clear();
      for (const sim::ImuSample& s : frame.imu) {
        vo::GyroSample g;
        g.time_s = s.time_s;
        g.rate_radps = s.gyro_radps;
        gyro.push_back(g);
      }
      odometry.AddGyroSamples(gyro);
    }
    if (source_frames++ % stride != 0) continue;  // frame stride: skip to every k-th frame
    FrameRecord record;
    record.source_index = source_frames - 1;
    record.time_s = frame.time_s;
    record.result = odometry.Process(frame.left, frame.right, frame.time_s);
    if (options.feedback) options.feedback(record.result);
    record.has_gt = frame.has_gt;
    record.T_world_cam0_gt = frame.T_world_cam0;
    const vo::TrackingStatus status = record.result.status;
    if (options.match_stats && frame.has_gt && !frame.depth_m.empty()) {
      GroundTruthFrame current;
      current.depth_m = frame.depth_m;
      current.T_world_cam0 = frame.T_world_cam0;
      if (have_reference_gt && status == vo::TrackingStatus::kTracking) {
        const vo::FrameDiagnostics d = odometry.last_diagnostics();
        AccumulateVoMatchStats(odometry.camera(), reference_gt, current, d.reference_features,
                               d.features, d.matches, d.inlier_mask, match_eval_options,
                               &r.match_stats);
      }
      if (status != vo::TrackingStatus::kLost) {
        reference_gt = current;
        have_reference_gt = true;
      }
    } else {
      have_reference_gt = false;
    }
    r.frames.push_back(std::move(record));
    progress.Update(static_cast<int>(r.frames.size()));
    if (InterruptSignal() != 0) {  // SIGINT/SIGTERM: the caller's work folder goes with it
      *error = InterruptedMessage(static_cast<int>(r.frames.size()), expected_vo_frames, "frames",
                                  options.out_dir);
      return false;
    }
  }
  if (!error->empty()) return false;
  progress.Finish(static_cast<int>(r.frames.size()));
  return true;
}

size_t FirstInitialisedFrame(const RunRecords& records) {
  size_t first = 0;
  while (first < records.frames.size() &&
         records.frames[first].result.status == vo::TrackingStatus::kLost)
    ++first;
  return first;
}

bool Summarize(const RunRecords& records, RunSummary* summary, std::string* error) {
  // A bad start is a bad start, not a wrong world: the frames before the first one the VO
  // initialised on have no pose; the world and the ground truth are anchored at that frame.
  const std::vector<FrameRecord>& all = records.frames;
  const size_t first = FirstInitialisedFrame(records);
  if (first == all.size()) {
    *error = records.name + ": the VO never initialised on any of the " +
             std::to_string(all.size()) + " frames (" +
             (all.empty() ? std::string("no frames") : all.back().result.message) + ")";
    return false;
  }
  if (all.size() - first < 2) {
    *error = records.name + ": fewer than 2 frames" +
             (first > 0 ? " after the first " + std::to_string(first) + " (not initialised)" : "");
    return false;
  }
  const FrameRecord& first_frame = all[first];  // the frames from it on are summarised
  RunSummary& s = *summary;
  s = RunSummary();
  s.name = records.name;
  std::vector<Eigen::Isometry3d> est_at_gt, gt_at_gt;  // the frames with ground truth
  for (size_t i = first; i < all.size(); ++i) {
    const FrameRecord& f = all[i];
    if (!f.has_gt) continue;
    est_at_gt.push_back(f.result.T_world_cam0);
    gt_at_gt.push_back(f.T_world_cam0_gt);
  }
  s.has_ground_truth = gt_at_gt.size() >= 2;
  s.ground_truth_frames = static_cast<int>(gt_at_gt.size());
  if (s.has_ground_truth) s.metrics = ComputeTrajectoryMetrics(est_at_gt, gt_at_gt);
  s.frame_stride = records.frame_stride;
  s.metrics.frames = static_cast<int>(all.size() - first);
  s.frames_not_initialised = static_cast<int>(first);
  std::vector<double> total, feats, inl;
  std::map<std::string, std::vector<double>> stages;
  for (size_t i = first; i < all.size(); ++i) {
    const vo::OdometryResult& r = all[i].result;
    if (vo::IsLostFrame(r)) {
      ++s.lost_frames;
      if (r.bridge_aligned) ++s.bridge_aligned_frames;
    }
    if (r.direct_motion) ++s.direct_motion_frames;
    if (r.reinitialised) ++s.reinitialisations;
    total.push_back(r.times.total_ms);
    feats.push_back(r.num_features_with_depth);
    inl.push_back(r.num_inliers);
    stages["disparity"].push_back(r.times.disparity_ms);
    stages["detect"].push_back(r.times.detect_ms);
    stages["depth"].push_back(r.times.depth_ms);
    stages["match"].push_back(r.times.match_ms);
    stages["motion"].push_back(r.times.motion_ms);
    stages["ba"].push_back(r.times.ba_ms);
    stages["predict"].push_back(r.times.predict_ms);
    stages["guided"].push_back(r.times.guided_ms);
  }
  // Timing excludes the first frame (initialisation with the plane fit).
  s.vo_ms_median = Median({total.begin() + 1, total.end()});
  s.vo_ms_p95 = Percentile({total.begin() + 1, total.end()}, 95.0);
  for (auto& [k, v] : stages) s.stage_ms_median[k] = Median({v.begin() + 1, v.end()});
  s.features_median = Median(feats);
  s.match_stats = records.match_stats;
  s.inliers_median = Median({inl.begin() + 1, inl.end()});
  s.initial_orientation_ok = first_frame.result.initial_orientation_ok;
  s.initial_floor_refined = first_frame.result.floor_refined;
  s.initial_floor_message = first_frame.result.floor_refinement_message;
  if (!s.has_ground_truth) {
    s.initial_orientation_error_reason = "no ground truth";
  } else if (!first_frame.has_gt) {
    s.initial_orientation_error_reason = "no ground truth at the first initialised frame";
  } else if (!s.initial_orientation_ok) {
    s.initial_orientation_error_reason =
        "the first frame's orientation was not found from the hallway's planes";
  } else {
    s.initial_orientation_error_deg = RotationAngle(first_frame.result.T_world_cam0.linear(),
                                                    first_frame.T_world_cam0_gt.linear()) *
                                      180.0 / M_PI;
  }
  return true;
}

}  // namespace harness
