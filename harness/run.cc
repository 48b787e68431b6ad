#include "harness/run.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "harness/interrupt.h"
#include "harness/plots.h"
#include "harness/progress.h"
#include "harness/render.h"
#include "harness/trajectory_io.h"
#include "harness/vo_config.h"
#include "sim/simulator.h"

namespace harness {
namespace {

namespace fs = std::filesystem;

std::vector<StampedPose> Stamped(const std::vector<double>& t, const std::vector<Eigen::Isometry3d>& T) {
  std::vector<StampedPose> out;
  for (size_t i = 0; i < T.size(); ++i) out.push_back({t[i], T[i]});
  return out;
}

std::string Fmt(double v, int prec = 4) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(prec);
  s << v;
  return s.str();
}

std::string ReportMarkdown(const RunSummary& s, const std::string& options_yaml) {
  const TrajectoryMetrics& m = s.metrics;
  std::ostringstream r;
  r << "# vobench run: " << s.name << "\n\n";
  r << "| metric | value |\n| --- | --- |\n";
  r << "| frames | " << m.frames << " |\n";
  r << "| frames with ground truth | " << s.ground_truth_frames
    << (s.has_ground_truth ? " (the metrics below use these)" : " (no accuracy metrics)") << " |\n";
  if (s.has_ground_truth) {
    r << "| path length (ground truth) | " << Fmt(m.path_length_m, 3) << " m |\n";
    r << "| end-pose error | " << Fmt(m.end_pose_error_m) << " m (" << Fmt(m.end_pose_error_pct, 2) << " % of the path) |\n";
    r << "| end rotation error | " << Fmt(m.end_rotation_error_deg, 3) << " deg |\n";
    r << "| ATE RMSE (SE(3)-aligned) | " << Fmt(m.ate_rmse_m) << " m |\n";
    r << "| ATE RMSE (from the common start) | " << Fmt(m.ate_rmse_unaligned_m) << " m |\n";
    r << "| RPE per frame (translation / rotation) | " << Fmt(m.rpe_trans_rmse_m * 1000, 2) << " mm / " << Fmt(m.rpe_rot_rmse_deg, 4) << " deg |\n";
    if (s.match_stats.matches > 0)
      r << "| VO matches correct (all / RANSAC inliers), vs ground truth | " << Fmt(100.0 * s.match_stats.precision(), 2) << " % / " << Fmt(100.0 * s.match_stats.inlier_precision(), 2) << " % of " << s.match_stats.matches << " |\n";
    r << "| RPE per " << Fmt(m.rpe_distance_step_m, 1) << " m (translation / rotation) | " << Fmt(m.rpe_distance_trans_rmse_m * 1000, 1) << " mm / " << Fmt(m.rpe_distance_rot_rmse_deg, 3) << " deg |\n";
    r << "| drift (KITTI-style, 1/8..8/8 of the path) | " << Fmt(m.drift_pct, 3) << " % / " << Fmt(m.drift_deg_per_m, 4) << " deg/m |\n";
    if (s.initial_orientation_error_deg >= 0)
      r << "| initial orientation from planes (error vs GT) | " << (s.initial_orientation_ok ? "found" : "not found") << ", " << Fmt(s.initial_orientation_error_deg, 2) << " deg |\n";
  }
  r << "| lost frames (no measured motion) / re-initialisations | " << s.lost_frames << " / "
    << s.reinitialisations << " |\n";
  if (s.frames_not_initialised > 0) {
    r << "| frames before the VO initialised (no pose, not evaluated) | " << s.frames_not_initialised
      << " |\n";
  }
  r << "| VO time per frame, median / p95 | " << Fmt(s.vo_ms_median, 2) << " / " << Fmt(s.vo_ms_p95, 2) << " ms |\n";
  for (const auto& [k, v] : s.stage_ms_median) r << "| stage median: " << k << " | " << Fmt(v, 2) << " ms |\n";
  r << "\n![trajectory](trajectory.png)\n\n![errors](errors.png)\n\n![timing](timing.png)\n\n";
  r << "Effective VO options (`vobench run --config` accepts this file as `vo_options.yaml`):\n\n```yaml\n" << options_yaml << "```\n";
  return r.str();
}

}  // namespace

std::string MetricsJson(const RunSummary& s) {
  nlohmann::ordered_json j;
  const TrajectoryMetrics& m = s.metrics;
  j["name"] = s.name;
  j["frames"] = m.frames;
  j["frame_stride"] = s.frame_stride;
  j["has_ground_truth"] = s.has_ground_truth;
  j["ground_truth_frames"] = s.ground_truth_frames;
  if (s.has_ground_truth) {  // without ground truth there is nothing to compare with
    j["path_length_m"] = m.path_length_m;
    j["end_pose_error_m"] = m.end_pose_error_m;
    j["end_pose_error_pct"] = m.end_pose_error_pct;
    j["end_rotation_error_deg"] = m.end_rotation_error_deg;
    j["ate_rmse_m"] = m.ate_rmse_m;
    j["ate_rmse_unaligned_m"] = m.ate_rmse_unaligned_m;
    j["rpe_trans_rmse_m"] = m.rpe_trans_rmse_m;
    j["rpe_rot_rmse_deg"] = m.rpe_rot_rmse_deg;
    j["rpe_distance_step_m"] = m.rpe_distance_step_m;
    j["rpe_distance_trans_rmse_m"] = m.rpe_distance_trans_rmse_m;
    j["rpe_distance_rot_rmse_deg"] = m.rpe_distance_rot_rmse_deg;
    j["drift_pct"] = m.drift_pct;
    j["drift_deg_per_m"] = m.drift_deg_per_m;
  }
  if (s.match_stats.matches > 0) {
    j["matches_evaluated"] = s.match_stats.matches;
    j["match_precision"] = s.match_stats.precision();
    j["inlier_match_precision"] = s.match_stats.inlier_precision();
  }
  j["lost_frames"] = s.lost_frames;
  j["frames_not_initialised"] = s.frames_not_initialised;
  j["reinitialisations"] = s.reinitialisations;
  j["vo_ms_median"] = s.vo_ms_median;
  j["vo_ms_p95"] = s.vo_ms_p95;
  for (const auto& [k, v] : s.stage_ms_median) j["stage_ms_median"][k] = v;
  j["features_median"] = s.features_median;
  j["inliers_median"] = s.inliers_median;
  j["initial_orientation_ok"] = s.initial_orientation_ok;
  j["initial_orientation_error_deg"] = s.initial_orientation_error_deg;
  return j.dump(2) + "\n";
}

bool RunOdometry(const std::string& name, const vo::StereoCamera& camera, FrameSource source,
                 int expected_frames, const vo::OdometryOptions& vo_options, const RunOptions& options,
                 const std::string& scenario_yaml, RunSummary* summary, std::string* error) {
  if (options.frame_stride < 1) {
    *error = "frame stride must be >= 1, got " + std::to_string(options.frame_stride);
    return false;
  }
  auto odometry = vo::StereoOdometry::Create(camera, vo_options, error);
  if (!odometry) {
    *error = "invalid VO options or camera: " + *error;
    return false;
  }
  const fs::path dir = options.out_dir;
  if (fs::exists(dir) && !fs::exists(dir / "metrics.json")) {
    *error = dir.string() + ": exists and is not a vobench run folder (no metrics.json); choose another --out";
    return false;
  }
  PartialFolder folder;  // the run folder is written as DIR.partial and moved into place
  if (!folder.Create(dir.string(), error)) return false;

  std::vector<double> times;
  std::vector<Eigen::Isometry3d> est, gt;
  std::vector<vo::OdometryResult> results;
  std::vector<size_t> gt_frames;  // indices of the frames with ground truth
  const int stride = options.frame_stride;
  if (options.max_frames > 0 && (expected_frames <= 0 || expected_frames > options.max_frames))
    expected_frames = options.max_frames;
  const int expected_vo_frames = (expected_frames + stride - 1) / stride;
  Progress progress("vo " + name, expected_vo_frames, options.progress);
  DatasetFrame frame;
  // Matcher statistics where the ground truth allows (frames with depth and pose): the VO's
  // matches to its reference frame (the last frame that was not lost) checked against them.
  VoMatchStats match_stats;
  const MatchEvalOptions match_eval_options;
  GroundTruthFrame reference_gt;
  bool have_reference_gt = false;
  int source_frames = 0;
  while ((options.max_frames <= 0 || source_frames < options.max_frames) && source(&frame, error)) {
    if (source_frames++ % stride != 0) continue;  // frame stride: skip to every k-th frame
    results.push_back(odometry->Process(frame.left, frame.right, frame.time_s));
    if (frame.has_gt && !frame.depth_m.empty()) {
      GroundTruthFrame current;
      current.depth_m = frame.depth_m;
      current.T_world_cam0 = frame.T_world_cam0;
      if (have_reference_gt && results.back().status == vo::TrackingStatus::kTracking) {
        AccumulateVoMatchStats(camera, reference_gt, current, odometry->last_reference_features(),
                               odometry->last_features(), odometry->last_matches(),
                               odometry->last_inlier_mask(), match_eval_options, &match_stats);
      }
      if (results.back().status != vo::TrackingStatus::kLost) {
        reference_gt = current;
        have_reference_gt = true;
      }
    } else {
      have_reference_gt = false;
    }
    times.push_back(frame.time_s);
    est.push_back(results.back().T_world_cam0);
    if (frame.has_gt) gt_frames.push_back(results.size() - 1);
    gt.push_back(frame.T_world_cam0);
    progress.Update(static_cast<int>(results.size()));
    if (InterruptSignal() != 0) {  // SIGINT/SIGTERM: the partial folder goes with `folder`
      *error = InterruptedMessage(static_cast<int>(results.size()), expected_vo_frames, "frames",
                                  options.out_dir);
      return false;
    }
  }
  if (!error->empty()) return false;
  progress.Finish(static_cast<int>(results.size()));
  // A bad start is a bad start, not a wrong world: the frames before the first one the VO
  // initialised on (black, over-exposed, textureless) have no pose. They are listed in
  // per_frame.csv as not_initialised and left out of the trajectories and the metrics, whose
  // world and ground truth are anchored at that first frame.
  size_t first = 0;
  while (first < results.size() && results[first].status == vo::TrackingStatus::kLost) ++first;
  if (first == results.size()) {
    *error = name + ": the VO never initialised on any of the " + std::to_string(results.size()) +
             " frames (" + (results.empty() ? std::string("no frames") : results.back().message) + ")";
    return false;
  }
  const std::vector<vo::OdometryResult> not_initialised(results.begin(), results.begin() + first);
  results.erase(results.begin(), results.begin() + first);
  est.erase(est.begin(), est.begin() + first);
  gt.erase(gt.begin(), gt.begin() + first);
  times.erase(times.begin(), times.begin() + first);
  std::vector<size_t> kept_gt_frames;
  for (size_t i : gt_frames) {
    if (i >= first) kept_gt_frames.push_back(i - first);
  }
  gt_frames.swap(kept_gt_frames);
  if (results.size() < 2) {
    *error = name + ": fewer than 2 frames" +
             (first > 0 ? " after the first " + std::to_string(first) + " (not initialised)" : "");
    return false;
  }

  // Summary.
  RunSummary& s = *summary;
  s = RunSummary();
  s.name = name;
  const bool has_gt = gt_frames.size() >= 2;
  const bool all_gt = gt_frames.size() == results.size();
  s.has_ground_truth = has_gt;
  s.ground_truth_frames = static_cast<int>(gt_frames.size());
  std::vector<Eigen::Isometry3d> est_at_gt, gt_at_gt;  // the frames with ground truth
  std::vector<double> times_at_gt;
  for (size_t i : gt_frames) {
    est_at_gt.push_back(est[i]);
    gt_at_gt.push_back(gt[i]);
    times_at_gt.push_back(times[i]);
  }
  if (has_gt) s.metrics = ComputeTrajectoryMetrics(est_at_gt, gt_at_gt);
  s.frame_stride = stride;
  s.metrics.frames = static_cast<int>(results.size());
  s.frames_not_initialised = static_cast<int>(first);
  std::vector<double> total, feats, inl;
  std::map<std::string, std::vector<double>> stages;
  for (const auto& r : results) {
    if (vo::IsLostFrame(r)) ++s.lost_frames;
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
  s.match_stats = match_stats;
  s.inliers_median = Median({inl.begin() + 1, inl.end()});
  s.initial_orientation_ok = results.front().initial_orientation_ok;
  if (has_gt && gt_frames.front() == 0 && s.initial_orientation_ok)
    s.initial_orientation_error_deg = RotationAngle(est.front().linear(), gt.front().linear()) * 180.0 / M_PI;

  // Files.
  const fs::path p = folder.path();
  // Errors per frame relative to the first frame with ground truth; "nan" for frames without.
  const size_t g0 = gt_frames.empty() ? 0 : gt_frames.front();
  std::vector<Eigen::Isometry3d> anchored;
  if (has_gt)
    for (const auto& T : est) anchored.push_back(gt[g0] * est[g0].inverse() * T);
  std::vector<double> dist(results.size(), std::nan("")), te_m(results.size(), std::nan("")),
      re_deg(results.size(), std::nan(""));
  if (has_gt) {
    const std::vector<double> d = CumulativeDistance(RelativeToFirst(gt_at_gt));
    for (size_t k = 0; k < gt_frames.size(); ++k) {
      const size_t i = gt_frames[k];
      const Eigen::Isometry3d e = est[g0].inverse() * est[i], g = gt[g0].inverse() * gt[i];
      dist[i] = d[k];
      te_m[i] = (e.translation() - g.translation()).norm();
      re_deg[i] = RotationAngle(e.linear(), g.linear()) * 180.0 / M_PI;
    }
  }
  std::ostringstream csv;
  csv << "frame,time_s,status,features,features_with_depth,matches,inliers,rms_reprojection_px,ba_ran,"
         "disparity_ms,detect_ms,depth_ms,match_ms,motion_ms,ba_ms,total_ms,x_m,y_m,z_m,gt_distance_m,"
         "translation_error_m,rotation_error_deg,motion_measured,reinitialised,prediction,"
         "first_pass_inliers,image_shift_x_px,image_shift_y_px,predict_ms,guided_ms,num_disparities,"
         "disparity_pixels\n";
  // One row per frame; frames before the first initialised one have no pose and no error.
  const double kNan = std::nan("");
  auto row = [&](size_t frame, double time_s, const std::string& status, const vo::OdometryResult& r,
                 const Eigen::Vector3d& t, double dist_m, double te, double re) {
    csv << frame << "," << FormatDouble(time_s) << "," << status << "," << r.num_features << ","
        << r.num_features_with_depth << "," << r.num_matches << "," << r.num_inliers << "," << Fmt(r.rms_reprojection_px)
        << "," << (r.ba_ran ? 1 : 0) << "," << Fmt(r.times.disparity_ms, 3) << "," << Fmt(r.times.detect_ms, 3) << ","
        << Fmt(r.times.depth_ms, 3) << "," << Fmt(r.times.match_ms, 3) << "," << Fmt(r.times.motion_ms, 3) << ","
        << Fmt(r.times.ba_ms, 3) << "," << Fmt(r.times.total_ms, 3) << "," << FormatDouble(t.x()) << ","
        << FormatDouble(t.y()) << "," << FormatDouble(t.z()) << "," << Fmt(dist_m) << ","
        << Fmt(te, 6) << "," << Fmt(re, 5) << "," << (r.motion_measured ? 1 : 0) << ","
        << (r.reinitialised ? 1 : 0) << "," << vo::ToString(r.prediction) << "," << r.num_first_pass_inliers
        << "," << Fmt(r.image_shift_px.x(), 2) << "," << Fmt(r.image_shift_px.y(), 2) << ","
        << Fmt(r.times.predict_ms, 3) << "," << Fmt(r.times.guided_ms, 3) << "," << r.num_disparities << ","
        << r.disparity_pixels << "\n";
  };
  for (size_t i = 0; i < not_initialised.size(); ++i) {
    const vo::OdometryResult& r = not_initialised[i];
    row(i, r.time_s, "not_initialised", r, Eigen::Vector3d::Constant(kNan), kNan, kNan, kNan);
  }
  for (size_t i = 0; i < results.size(); ++i) {
    row(i + first, times[i], vo::ToString(results[i].status), results[i], est[i].translation(), dist[i],
        te_m[i], re_deg[i]);
  }
  const std::string options_yaml = VoConfigToYaml(odometry->options());
  if (!WriteTum((p / "trajectory_tum.txt").string(), Stamped(times, est), error) ||
      !WriteKittiPoses((p / "trajectory_kitti.txt").string(), est, error) ||
      !WriteTextFile((p / "per_frame.csv").string(), csv.str(), error) ||
      !WriteTextFile((p / "vo_options.yaml").string(), options_yaml, error) ||
      !WriteTextFile((p / "metrics.json").string(), MetricsJson(s), error))
    return false;
  if (!scenario_yaml.empty() && !WriteTextFile((p / "scenario.yaml").string(), scenario_yaml, error)) return false;
  if (has_gt) {
    // groundtruth_kitti.txt has no stamps: written only when it lines up with the estimate.
    if (!WriteTum((p / "groundtruth_tum.txt").string(), Stamped(times_at_gt, gt_at_gt), error) ||
        (all_gt && !WriteKittiPoses((p / "groundtruth_kitti.txt").string(), gt, error)) ||
        !WriteTum((p / "estimate_in_gt_world_tum.txt").string(), Stamped(times, anchored), error))
      return false;
  }
  if (options.plots) {
    std::string plot_error;
    bool ok = true;
    if (has_gt) {
      ok = RunTrajectoryPlot((p / "groundtruth_tum.txt").string(),
                             (p / "estimate_in_gt_world_tum.txt").string(),
                             (p / "trajectory.png").string(), options.outline_scene, &plot_error) &&
           RunPlot({"errors", p.string(), (p / "errors.png").string()}, &plot_error);
    }
    ok = ok && RunPlot({"timing", p.string(), (p / "timing.png").string()}, &plot_error);
    if (!ok) std::fprintf(stderr, "warning: plots not made: %s\n", plot_error.c_str());
  }
  if (!WriteTextFile((p / "report.md").string(), ReportMarkdown(s, options_yaml), error)) return false;
  if (InterruptSignal() != 0) {  // during the plots or the files: still nothing published
    *error = InterruptedMessage(static_cast<int>(results.size()), static_cast<int>(results.size()),
                                "frames", options.out_dir);
    return false;
  }
  return folder.Publish("metrics.json", "run", error);
}

bool RunScenario(const sim::Scenario& scenario, const vo::OdometryOptions& vo_options,
                 const RunOptions& options, RunSummary* summary, std::string* error) {
  auto simulator = sim::Simulator::Create(scenario, error);
  if (!simulator) return false;
  RunOptions o = options;
  if (o.outline_scene.empty()) o.outline_scene = scenario.scene_path;
  sim::StereoFrame f;
  FrameSource source = [&](DatasetFrame* frame, std::string* err) {
    if (!simulator->Next(&f, err)) return false;
    *frame = ToDatasetFrame(f);
    return true;
  };
  return RunOdometry(scenario.name, ToStereoCamera(simulator->calibration()), source, simulator->EstimatedFrames(),
                     vo_options, o, sim::ScenarioToYaml(scenario), summary, error);
}

bool RunKittiDataset(const std::string& dir, const vo::OdometryOptions& vo_options, const RunOptions& options,
                     RunSummary* summary, std::string* error) {
  KittiReader reader;
  if (!reader.Open(dir, error)) return false;
  size_t next = 0;
  FrameSource source = [&](DatasetFrame* frame, std::string* err) {
    if (next >= reader.size()) return false;
    return reader.ReadFrame(next++, frame, err);
  };
  return RunOdometry(fs::path(dir).filename().string(), reader.camera(), source, static_cast<int>(reader.size()),
                     vo_options, options, "", summary, error);
}

}  // namespace harness
