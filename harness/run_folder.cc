#include "harness/run_folder.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "harness/interrupt.h"
#include "harness/metric_registry.h"
#include "harness/plots/plots.h"

namespace harness {
namespace {

namespace fs = std::filesystem;

std::vector<StampedPose> Stamped(const std::vector<double>& t,
                                 const std::vector<Eigen::Isometry3d>& T) {
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

// A CSV field (RFC 4180): in double quotes, a quote doubled, a line break as a space.
std::string CsvQuoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return out + "\"";
}

// A figure, or "n/a (why)" when it does not apply (NaN).
std::string FmtOrNa(double v, int prec, const std::string& unit, const std::string& why) {
  return std::isfinite(v) ? Fmt(v, prec) + unit : "n/a (" + why + ")";
}

// `folder`: the run folder being written; the report links only the plots that are in it.
std::string ReportMarkdown(const RunSummary& s, const std::string& options_yaml,
                           const fs::path& folder) {
  const TrajectoryMetrics& m = s.metrics;
  std::ostringstream r;
  r << "# vobench run: " << s.name << "\n\n";
  r << "| metric | value |\n| --- | --- |\n";
  r << "| frames | " << m.frames << " |\n";
  r << "| frames with ground truth | " << s.ground_truth_frames
    << (s.has_ground_truth ? " (the metrics below use these)" : " (no accuracy metrics)") << " |\n";
  if (s.has_ground_truth) {
    r << "| path length (ground-truth camera, 3-D) | " << Fmt(m.path_length_m, 3) << " m |\n";
    r << "| end-pose error | " << Fmt(m.end_pose_error_m) << " m ("
      << FmtOrNa(m.end_pose_error_pct, 2, " % of the path", m.end_pose_error_pct_reason) << ") |\n";
    r << "| end rotation error | " << Fmt(m.end_rotation_error_deg, 3) << " deg |\n";
    r << "| ATE RMSE (SE(3)-aligned) | " << Fmt(m.ate_rmse_m) << " m |\n";
    r << "| ATE RMSE (from the common start) | " << Fmt(m.ate_rmse_unaligned_m) << " m |\n";
    r << "| RPE per frame (translation / rotation) | " << Fmt(m.rpe_trans_rmse_m * 1000, 2)
      << " mm / " << Fmt(m.rpe_rot_rmse_deg, 4) << " deg |\n";
    if (s.match_stats.matches > 0)
      r << "| VO matches correct (all / RANSAC inliers), vs ground truth | "
        << Fmt(100.0 * s.match_stats.precision(), 2) << " % / "
        << Fmt(100.0 * s.match_stats.inlier_precision(), 2) << " % of " << s.match_stats.matches
        << " |\n";
    r << "| RPE per " << Fmt(m.rpe_distance_step_m, 1)
      << " m (evo_rpe --all_pairs; translation / rotation) | "
      << (m.rpe_distance_pairs > 0 ? Fmt(m.rpe_distance_trans_rmse_m * 1000, 1) + " mm / " +
                                         Fmt(m.rpe_distance_rot_rmse_deg, 3) + " deg"
                                   : "n/a (" + m.rpe_distance_reason + ")")
      << " |\n";
    r << "| drift (vobench: sub-paths of >= 1/8..8/8 of the path / their length) | "
      << (std::isfinite(m.drift_pct)
              ? Fmt(m.drift_pct, 3) + " % / " + Fmt(m.drift_deg_per_m, 4) + " deg/m"
              : "n/a (" + m.drift_reason + ")")
      << " |\n";
    r << "| drift (KITTI devkit: segments past L / L) | "
      << (std::isfinite(m.kitti_drift_pct)
              ? Fmt(m.kitti_drift_pct, 3) + " % / " + Fmt(m.kitti_drift_deg_per_m, 4) +
                    " deg/m over " + std::to_string(m.kitti_drift_segments) + " segments"
              : "n/a (" + m.kitti_drift_reason + ")")
      << " |\n";
    r << "| initial orientation from planes (error vs GT) | "
      << (s.initial_orientation_ok ? "found" : "not found") << ", "
      << FmtOrNa(s.initial_orientation_error_deg, 2, " deg", s.initial_orientation_error_reason)
      << (s.initial_floor_message.empty() ? "" : "; " + s.initial_floor_message) << " |\n";
  }
  r << "| lost frames (no measured motion) / re-initialisations | " << s.lost_frames << " / "
    << s.reinitialisations << " |\n";
  if (s.bridge_aligned_frames > 0) {
    r << "| lost frames whose bridged step or yaw was measured (vehicle_bridge_alignment) | "
      << s.bridge_aligned_frames << " |\n";
  }
  if (s.direct_motion_frames > 0) {
    r << "| frames without features enough, measured by direct image alignment "
         "(vehicle_direct_alignment) | "
      << s.direct_motion_frames << " |\n";
  }
  if (s.frames_not_initialised > 0) {
    r << "| frames before the VO initialised (no pose, not evaluated) | "
      << s.frames_not_initialised << " |\n";
  }
  if (s.has_navigation) {
    const sim::NavigationReport& n = s.navigation;
    r << "| navigation (what the follower steered on) | " << n.mode << " |\n";
    r << "| goal reached / end error of the robot | " << (n.reached_goal ? "yes" : "no") << " / "
      << FmtOrNa(n.end_error_m, 3, " m", "no end") << " |\n";
    r << "| largest waypoint error (when believed reached) | "
      << FmtOrNa(n.max_waypoint_error_m, 3, " m", "none reached") << " |\n";
    r << "| wall contacts | "
      << (n.wall_contacts < 0
              ? std::string("n/a (the scene's walls do not collide)")
              : std::to_string(n.wall_contacts) + " (" + Fmt(n.wall_contact_s, 2) + " s)")
      << " |\n";
  }
  r << "| VO time per frame, median / p95 | " << Fmt(s.vo_ms_median, 2) << " / "
    << Fmt(s.vo_ms_p95, 2) << " ms |\n";
  for (const auto& [k, v] : s.stage_ms_median)
    r << "| stage median: " << k << " | " << Fmt(v, 2) << " ms |\n";
  r << "\n";
  for (const char* plot : {"trajectory", "errors", "timing"})  // only the plots made
    if (fs::exists(folder / (std::string(plot) + ".png")))
      r << "![" << plot << "](" << plot << ".png)\n\n";
  r << "Effective VO options (`vobench run --config` accepts this file as "
       "`vo_options.yaml`):\n\n```yaml\n"
    << options_yaml << "```\n";
  return r.str();
}

// The trajectories of the initialised frames: stamps, estimate, ground truth; `gt_frames`
// indexes the frames with ground truth.
struct Trajectories {
  std::vector<double> times;
  std::vector<Eigen::Isometry3d> est, gt;
  std::vector<size_t> gt_frames;
};

Trajectories InitialisedTrajectories(const RunRecords& records, size_t first) {
  Trajectories t;
  for (size_t i = first; i < records.frames.size(); ++i) {
    const FrameRecord& f = records.frames[i];
    if (f.has_gt) t.gt_frames.push_back(t.times.size());
    t.times.push_back(f.time_s);
    t.est.push_back(f.result.T_world_cam0);
    t.gt.push_back(f.T_world_cam0_gt);
  }
  return t;
}

// The estimate anchored at the first frame with ground truth (the ground truth's world).
std::vector<Eigen::Isometry3d> AnchoredEstimate(const Trajectories& t) {
  std::vector<Eigen::Isometry3d> anchored;
  const size_t g0 = t.gt_frames.front();
  for (const auto& T : t.est) anchored.push_back(t.gt[g0] * t.est[g0].inverse() * T);
  return anchored;
}

// The poses relative to the first (the first exactly the identity): KITTI's convention for a
// trajectory file, which has no stamps and no world of its own (evo's kitti mode and the devkit
// compare such files without alignment).
std::vector<Eigen::Isometry3d> KittiRelativeToFirst(const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<Eigen::Isometry3d> relative;
  for (size_t i = 0; i < poses.size(); ++i)
    relative.push_back(i == 0 ? Eigen::Isometry3d::Identity() : poses[0].inverse() * poses[i]);
  return relative;
}

}  // namespace

std::string NavigationCsv(const sim::NavigationReport& n) {
  std::ostringstream csv;
  csv << "frame,time_s,believed_x_m,believed_y_m,believed_yaw_deg,true_x_m,true_y_m,true_yaw_deg,"
         "fixed\n";
  for (size_t i = 0; i < n.frames.size(); ++i) {
    const sim::NavigationFrame& f = n.frames[i];
    csv << i << "," << FormatDouble(f.time_s) << "," << FormatDouble(f.believed.position.x()) << ","
        << FormatDouble(f.believed.position.y()) << ","
        << FormatDouble(f.believed.yaw_rad * 180.0 / M_PI) << ","
        << FormatDouble(f.truth.position.x()) << "," << FormatDouble(f.truth.position.y()) << ","
        << FormatDouble(f.truth.yaw_rad * 180.0 / M_PI) << "," << (f.fixed ? 1 : 0) << "\n";
  }
  return csv.str();
}

namespace {

// PerFrameCsv on the trajectories WriteRunFolder has already made.
std::string PerFrameCsv(const RunRecords& records, const RunSummary& summary,
                        const Trajectories& t) {
  const size_t first = static_cast<size_t>(summary.frames_not_initialised);
  const size_t n = t.times.size();
  // Errors per frame relative to the first frame with ground truth; "nan" for frames without.
  std::vector<double> dist(n, std::nan("")), te_m(n, std::nan("")), re_deg(n, std::nan(""));
  if (summary.has_ground_truth) {
    std::vector<Eigen::Isometry3d> gt_at_gt;
    for (size_t i : t.gt_frames) gt_at_gt.push_back(t.gt[i]);
    const std::vector<double> d = CumulativeDistance(RelativeToFirst(gt_at_gt));
    const size_t g0 = t.gt_frames.front();
    for (size_t k = 0; k < t.gt_frames.size(); ++k) {
      const size_t i = t.gt_frames[k];
      const Eigen::Isometry3d e = t.est[g0].inverse() * t.est[i], g = t.gt[g0].inverse() * t.gt[i];
      dist[i] = d[k];
      te_m[i] = (e.translation() - g.translation()).norm();
      re_deg[i] = RotationAngle(e.linear(), g.linear()) * 180.0 / M_PI;
    }
  }
  std::ostringstream csv;
  csv << "frame,time_s,status,features,features_with_depth,matches,inliers,rms_reprojection_px,ba_"
         "ran,"
         "disparity_ms,detect_ms,depth_ms,match_ms,motion_ms,ba_ms,total_ms,x_m,y_m,z_m,gt_"
         "distance_m,"
         "translation_error_m,rotation_error_deg,motion_measured,reinitialised,prediction,"
         "first_pass_inliers,image_shift_x_px,image_shift_y_px,predict_ms,guided_ms,num_"
         "disparities,"
         "disparity_pixels,chained_to_frame,chain_inliers,bridge_aligned,few_point_motion,"
         "direct_motion,message\n";
  // One row per frame; frames before the first initialised one have no pose and no error.
  const double kNan = std::nan("");
  auto row = [&](size_t frame, double time_s, const std::string& status,
                 const vo::OdometryResult& r, const Eigen::Vector3d& p, double dist_m, double te,
                 double re) {
    csv << frame << "," << FormatDouble(time_s) << "," << status << "," << r.num_features << ","
        << r.num_features_with_depth << "," << r.num_matches << "," << r.num_inliers << ","
        << Fmt(r.rms_reprojection_px) << "," << (r.ba_ran ? 1 : 0) << ","
        << Fmt(r.times.disparity_ms, 3) << "," << Fmt(r.times.detect_ms, 3) << ","
        << Fmt(r.times.depth_ms, 3) << "," << Fmt(r.times.match_ms, 3) << ","
        << Fmt(r.times.motion_ms, 3) << "," << Fmt(r.times.ba_ms, 3) << ","
        << Fmt(r.times.total_ms, 3) << "," << FormatDouble(p.x()) << "," << FormatDouble(p.y())
        << "," << FormatDouble(p.z()) << "," << Fmt(dist_m) << "," << Fmt(te, 6) << ","
        << Fmt(re, 5) << "," << (r.motion_measured ? 1 : 0) << "," << (r.reinitialised ? 1 : 0)
        << "," << vo::ToString(r.prediction) << "," << r.num_first_pass_inliers << ","
        << Fmt(r.image_shift_px.x(), 2) << "," << Fmt(r.image_shift_px.y(), 2) << ","
        << Fmt(r.times.predict_ms, 3) << "," << Fmt(r.times.guided_ms, 3) << ","
        << r.num_disparities << "," << r.disparity_pixels << "," << r.chained_to_frame << ","
        << r.chain_inliers << "," << (r.bridge_aligned ? 1 : 0) << ","
        << (r.few_point_motion ? 1 : 0) << "," << (r.direct_motion ? 1 : 0) << ","
        << CsvQuoted(r.message) << "\n";
  };
  for (size_t i = 0; i < first; ++i) {
    const vo::OdometryResult& r = records.frames[i].result;
    row(i, r.time_s, "not_initialised", r, Eigen::Vector3d::Constant(kNan), kNan, kNan, kNan);
  }
  for (size_t i = 0; i < n; ++i) {
    const vo::OdometryResult& r = records.frames[first + i].result;
    row(i + first, t.times[i], vo::ToString(r.status), r, t.est[i].translation(), dist[i], te_m[i],
        re_deg[i]);
  }
  return csv.str();
}

}  // namespace

std::string PerFrameCsv(const RunRecords& records, const RunSummary& summary) {
  return PerFrameCsv(
      records, summary,
      InitialisedTrajectories(records, static_cast<size_t>(summary.frames_not_initialised)));
}

bool OpenRunFolder(const std::string& dir, OutputFolder* folder, std::string* error) {
  return folder->Create(dir, "run", error);
}

void MakePlots(const std::string& folder, bool has_ground_truth, const std::string& outline_scene) {
  const fs::path p = folder;
  std::string plot_error;
  bool ok = true;
  if (has_ground_truth) {
    const fs::path navigation = p / "navigation.csv";  // a closed-loop run's
    ok = RunTrajectoryPlot((p / "groundtruth_world_tum.txt").string(),
                           (p / "estimate_in_gt_world_tum.txt").string(),
                           (p / "trajectory.png").string(), outline_scene, &plot_error,
                           fs::exists(navigation) ? navigation.string() : "") &&
         RunPlot({"errors", p.string(), (p / "errors.png").string()}, &plot_error);
  }
  ok = ok && RunPlot({"timing", p.string(), (p / "timing.png").string()}, &plot_error);
  if (!ok) {
    // No plot at all rather than a half-written one (a full disk cuts a PNG short).
    std::error_code ec;
    for (const char* png : {"trajectory.png", "errors.png", "timing.png"}) fs::remove(p / png, ec);
    std::fprintf(stderr, "warning: plots not made: %s\n", plot_error.c_str());
  }
}

bool WriteRunFolder(const RunRecords& records, const RunSummary& s,
                    const RunFolderContents& contents, const std::string& dir, OutputFolder* folder,
                    std::string* error) {
  const fs::path p = folder->path();
  const Trajectories t =
      InitialisedTrajectories(records, static_cast<size_t>(s.frames_not_initialised));
  if (!WriteTum((p / "trajectory_world_tum.txt").string(), Stamped(t.times, t.est), error) ||
      !WriteKittiPoses((p / "trajectory_kitti.txt").string(), KittiRelativeToFirst(t.est), error) ||
      !WriteTextFile((p / "per_frame.csv").string(), PerFrameCsv(records, s, t), error) ||
      !WriteTextFile((p / "vo_options.yaml").string(), contents.options_yaml, error) ||
      !WriteTextFile((p / "metrics.json").string(), MetricsJson(s), error))
    return false;
  if (!contents.scenario_yaml.empty() &&
      !WriteTextFile((p / "scenario.yaml").string(), contents.scenario_yaml, error))
    return false;
  if (s.has_navigation && s.navigation.mode == "vo" &&
      !WriteTextFile((p / "navigation.csv").string(), NavigationCsv(s.navigation), error))
    return false;
  if (s.has_ground_truth) {
    std::vector<double> times_at_gt;
    std::vector<Eigen::Isometry3d> gt_at_gt;
    for (size_t i : t.gt_frames) {
      times_at_gt.push_back(t.times[i]);
      gt_at_gt.push_back(t.gt[i]);
    }
    // groundtruth_kitti.txt has no stamps: written only when it lines up with the estimate.
    const bool all_gt = t.gt_frames.size() == t.times.size();
    if (!WriteTum((p / "groundtruth_world_tum.txt").string(), Stamped(times_at_gt, gt_at_gt),
                  error) ||
        (all_gt && !WriteKittiPoses((p / "groundtruth_kitti.txt").string(),
                                    KittiRelativeToFirst(t.gt), error)) ||
        !WriteTum((p / "estimate_in_gt_world_tum.txt").string(),
                  Stamped(t.times, AnchoredEstimate(t)), error))
      return false;
  }
  if (contents.plots) MakePlots(p.string(), s.has_ground_truth, contents.outline_scene);
  if (!WriteTextFile((p / "report.md").string(), ReportMarkdown(s, contents.options_yaml, p),
                     error))
    return false;
  const int frames = static_cast<int>(t.times.size());
  if (InterruptSignal() != 0) {  // during the plots or the files: still nothing published
    *error = InterruptedMessage(frames, frames, "frames", dir);
    return false;
  }
  return folder->Publish(error);
}

}  // namespace harness
