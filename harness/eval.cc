#include "harness/eval.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <vector>

#include "harness/dataset/kalibr.h"
#include "harness/dataset/rig.h"
#include "harness/trajectory_io.h"

namespace harness {
namespace {

namespace fs = std::filesystem;

bool Fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

// Number of fields on the first line that is not blank or a comment (0 when none or unreadable).
size_t FirstLineFields(const std::string& path) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, nullptr)) return 0;
  for (const std::string& line : lines) {
    if (IsBlankOrComment(line)) continue;
    std::string text = line;
    std::replace(text.begin(), text.end(), ',', ' ');
    std::istringstream in(text);
    size_t n = 0;
    for (std::string field; in >> field;) ++n;
    return n;
  }
  return 0;
}

// One opener per layout: the reader (kept alive by the sequence's source), the camera the VO
// runs with, and what `eval` reports of the dataset.
bool OpenKitti(const std::string& dir, const EvalOptions& options, StereoSequence* sequence,
               EvalInfo* info, std::string* error) {
  // --gt in the KITTI poses format (12 numbers per line, one per frame, the KITTI benchmark's
  // poses/NN.txt) goes to the reader; a TUM trajectory is associated by stamp below.
  const bool kitti_poses = !options.gt_path.empty() && FirstLineFields(options.gt_path) == 12;
  auto reader = std::make_shared<KittiReader>();
  KittiReader::Options reader_options;
  if (kitti_poses) reader_options.poses_path = options.gt_path;
  if (!reader->Open(dir, reader_options, error)) return false;
  info->dataset_frames = reader->size();
  info->camera = reader->camera();
  // --gt: a TUM trajectory of the left camera, associated by stamp; replaces poses.txt.
  auto external = std::make_shared<std::vector<StampedPose>>();
  auto gt_index = std::make_shared<std::vector<long>>();
  if (kitti_poses) {
    info->ground_truth_path = options.gt_path;
    info->ground_truth_frames = reader->size();
  } else if (!options.gt_path.empty()) {
    if (!ReadTum(options.gt_path, external.get(), error)) return false;
    *gt_index = AssociateGroundTruth(reader->times_s(), *external, info->max_difference_s);
    info->ground_truth_frames =
        std::count_if(gt_index->begin(), gt_index->end(), [](long i) { return i >= 0; });
    if (info->ground_truth_frames == 0)
      return Fail(error, options.gt_path + ": no ground-truth pose within " +
                             FormatDouble(info->max_difference_s) + " s of any of the " +
                             std::to_string(reader->size()) + " frames in " + dir +
                             "/times.txt: a different clock or the wrong file?");
    info->ground_truth_path = options.gt_path;
  } else if (reader->has_ground_truth()) {
    info->ground_truth_path = (fs::path(dir) / "poses.txt").string();
    info->ground_truth_frames = reader->size();
  }
  // poses.txt (or --gt in the KITTI format) is relative to the first camera unless
  // T_world_cam0first.txt places that camera in a gravity-aligned world.
  if (!info->ground_truth_path.empty() && gt_index->empty() &&
      !fs::exists(fs::path(dir) / "T_world_cam0first.txt"))
    sequence->ground_truth_not_gravity_aligned =
        "ground truth not gravity-aligned (KITTI layout without T_world_cam0first.txt: world = "
        "first camera)";
  sequence->camera = reader->camera();
  sequence->expected_frames = static_cast<int>(reader->size());
  sequence->next = [reader, external, gt_index, next = size_t{0}](DatasetFrame* frame,
                                                                  std::string* err) mutable {
    if (next >= reader->size()) return false;
    const size_t i = next++;
    if (!reader->ReadFrame(i, frame, err)) return false;
    if (!gt_index->empty()) {
      frame->has_gt = (*gt_index)[i] >= 0;
      frame->T_world_cam0 =
          frame->has_gt ? (*external)[(*gt_index)[i]].T_world_cam : Eigen::Isometry3d::Identity();
    }
    return true;
  };
  return true;
}

bool OpenEuroc(const std::string& dir, const EvalOptions& options, StereoSequence* sequence,
               EvalInfo* info, std::string* error) {
  auto reader = std::make_shared<EurocReader>();
  EurocReader::Options reader_options;
  reader_options.gt_path = options.gt_path;
  reader_options.gt_max_difference_s = info->max_difference_s;
  if (!reader->Open(dir, reader_options, error)) return false;
  auto rectification = std::make_shared<StereoRectification>();
  if (!reader->Rectification(options.rectification, rectification.get(), error)) return false;
  info->dataset_frames = reader->size();
  info->unpaired_frames = reader->unpaired_frames();
  info->ground_truth_path = reader->ground_truth_path();
  info->ground_truth_frames = reader->ground_truth_frames();
  info->rectified = !rectification->IsIdentity();
  info->camera = rectification->camera;
  sequence->camera = rectification->camera;
  sequence->has_imu = reader->has_imu();
  sequence->imu = reader->imu();
  if (sequence->has_imu) {
    // EuRoC's body frame is its IMU's (imu0's T_BS is the identity, in the real datasets and in
    // vobench's exports): the rectified left camera in the IMU frame is cam0's T_BS turned by
    // the rectification's rotation (a rotation about cam0's centre).
    sequence->T_imu_cam0 = RectifiedLeftIn(rectification->T_body_cam0, rectification->R_cam0_rect0);
    sequence->imu_extrinsics_known = true;
    info->imu_extrinsics_path = reader->cam0().path + " (T_BS: EuRoC's body is the IMU)";
  }
  sequence->expected_frames = static_cast<int>(reader->size());
  sequence->next = [reader, rectification, next = size_t{0}](DatasetFrame* frame,
                                                             std::string* err) mutable {
    if (next >= reader->size()) return false;
    if (!reader->ReadFrame(next++, frame, err)) return false;
    RectifyFrame(*rectification, frame);
    return true;
  };
  return true;
}

bool OpenTum(const std::string& dir, const EvalOptions& options, StereoSequence* sequence,
             EvalInfo* info, std::string* error) {
  auto reader = std::make_shared<TumReader>();
  TumReader::Options reader_options;
  reader_options.gt_path = options.gt_path;
  reader_options.gt_max_difference_s = info->max_difference_s;
  if (!reader->Open(dir, reader_options, error)) return false;
  info->dataset_frames = reader->size();
  info->unpaired_frames = reader->unpaired_frames();
  info->ground_truth_path = reader->ground_truth_path();
  info->ground_truth_frames = reader->ground_truth_frames();
  info->camera = reader->camera();
  sequence->camera = reader->camera();
  sequence->expected_frames = static_cast<int>(reader->size());
  sequence->next = [reader, next = size_t{0}](DatasetFrame* frame, std::string* err) mutable {
    if (next >= reader->size()) return false;
    return reader->ReadFrame(next++, frame, err);
  };
  return true;
}

bool OpenRosbag(const std::string& path, const EvalOptions& options, StereoSequence* sequence,
                EvalInfo* info, std::string* error) {
  if (!options.gt_path.empty())
    return Fail(error, "--gt: not read with --format rosbag (the ground truth is the bag's " +
                           options.rosbag_topics.ground_truth + " topic)");
  auto reader = std::make_shared<RosbagReader>();
  RosbagReader::Options reader_options;
  reader_options.topics = options.rosbag_topics;
  reader_options.calib_left = options.calib_left;
  reader_options.calib_right = options.calib_right;
  reader_options.gt_max_difference_s = info->max_difference_s;
  reader_options.rectification = options.rectification;
  if (!reader->Open(path, reader_options, error)) return false;
  info->dataset_frames = reader->size();
  info->unpaired_frames = reader->unpaired_frames();
  if (!reader->ground_truth_topic().empty())
    info->ground_truth_path = path + ":" + reader->ground_truth_topic();
  info->ground_truth_frames = reader->ground_truth_frames();
  info->rectified = !reader->rectification().IsIdentity();
  info->camera = reader->rectification().camera;
  sequence->camera = info->camera;
  sequence->has_imu = reader->has_imu();
  sequence->imu = reader->imu();
  // The IMU's mounting, which camera_info cannot hold: --imu-extrinsics, else Kalibr's
  // camchain-imucam.yaml beside the bag (render writes it), else the --calib files' cam0 T_BS
  // (EuRoC's body frame is its IMU's, as `--format euroc` takes it). Cam0's pose turned by the
  // rectification's rotation: the VO's camera is the rectified left one.
  const fs::path beside = fs::path(path).parent_path() / kKalibrCamchainFileName;
  std::error_code ec;
  Eigen::Isometry3d T_imu_cam0 = Eigen::Isometry3d::Identity();
  if (!options.imu_extrinsics.empty()) {
    if (!sequence->has_imu)
      return Fail(error, "--imu-extrinsics " + options.imu_extrinsics + ": " + path +
                             " has no IMU messages on " + options.rosbag_topics.imu +
                             " (--imu names the topic)");
    if (!ReadKalibrImuExtrinsics(options.imu_extrinsics, &T_imu_cam0, error)) return false;
    info->imu_extrinsics_path = options.imu_extrinsics;
  } else if (sequence->has_imu && fs::exists(beside, ec)) {
    if (!ReadKalibrImuExtrinsics(beside.string(), &T_imu_cam0, error)) return false;
    info->imu_extrinsics_path = beside.string();
  } else if (sequence->has_imu && !options.calib_left.empty()) {
    T_imu_cam0 = reader->rectification().T_body_cam0;  // the --calib file's, as the reader read it
    info->imu_extrinsics_path = options.calib_left + " (T_BS: EuRoC's body is the IMU)";
  }
  if (!info->imu_extrinsics_path.empty()) {
    sequence->T_imu_cam0 = RectifiedLeftIn(T_imu_cam0, reader->rectification().R_cam0_rect0);
    sequence->imu_extrinsics_known = true;
  }
  sequence->expected_frames = static_cast<int>(reader->size());
  sequence->next = [reader, next = size_t{0}](DatasetFrame* frame, std::string* err) mutable {
    if (next >= reader->size()) return false;
    return reader->ReadFrame(next++, frame, err);
  };
  return true;
}

}  // namespace

bool EvalOptions::IsValid(std::string* error) const {
  if (format != DatasetFormat::kKitti && format != DatasetFormat::kEuroc &&
      format != DatasetFormat::kTum && format != DatasetFormat::kRosbag)
    return Fail(error, "format must be kitti, euroc, tum or rosbag");
  if (!imu_extrinsics.empty() && format != DatasetFormat::kRosbag)
    return Fail(error,
                "--imu-extrinsics is read with --format rosbag only (a EuRoC folder's "
                "cam0 sensor.yaml holds the camera's pose on the IMU)");
  if (!std::isfinite(max_difference_s) || max_difference_s < 0.0)
    return Fail(error, "max difference must be finite and >= 0 (0 = the format's default), got " +
                           FormatDouble(max_difference_s));
  return rectification.IsValid(error);
}

double DefaultMaxDifference(DatasetFormat format) {
  if (format == DatasetFormat::kRosbag) return RosbagReader::Options().gt_max_difference_s;
  return format == DatasetFormat::kEuroc ? EurocReader::Options().gt_max_difference_s
                                         : TumReader::Options().gt_max_difference_s;
}

std::string DatasetName(const std::string& dir) {
  fs::path p = fs::path(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // "seq/" -> "seq"
  std::string name = p.filename().string();
  if (p.extension() == ".bag") name = p.stem().string();  // a bag: "seq.bag" -> "seq"
  return name.empty() || name == "." || name == ".." ? "dataset" : name;
}

bool OpenDataset(const std::string& dir, const EvalOptions& options, StereoSequence* sequence,
                 EvalInfo* info, std::string* error) {
  std::string why;
  if (!options.IsValid(&why)) return Fail(error, "eval options: " + why);
  *info = EvalInfo();
  info->max_difference_s = options.max_difference_s > 0.0 ? options.max_difference_s
                                                          : DefaultMaxDifference(options.format);
  *sequence = StereoSequence();
  sequence->name = DatasetName(dir);
  const auto open = [&]() {
    switch (options.format) {
      case DatasetFormat::kKitti:
        return OpenKitti(dir, options, sequence, info, error);
      case DatasetFormat::kEuroc:
        return OpenEuroc(dir, options, sequence, info, error);
      case DatasetFormat::kTum:
        return OpenTum(dir, options, sequence, info, error);
      case DatasetFormat::kRosbag:
        return OpenRosbag(dir, options, sequence, info, error);
    }
    return Fail(error, "unknown dataset format");
  };
  if (!open()) return false;
  // The camera's mounting, when the folder says (vobench render writes it; a bag: its folder):
  // a ground vehicle then takes the rig's axle and pitch (vo::ResolvePlatform).
  const fs::path rig_path =
      (options.format == DatasetFormat::kRosbag ? fs::path(dir).parent_path() : fs::path(dir)) /
      kRigFileName;
  std::error_code ec;
  if (fs::exists(rig_path, ec)) {
    RigMounting rig;
    if (!ReadRigYaml(rig_path.string(), &rig, error)) return false;
    sequence->axle_behind_camera_m = rig.forward_m;
    sequence->camera_pitch_deg = rig.pitch_deg;
  }
  return true;
}

bool EvalDataset(const std::string& dir, const EvalOptions& options,
                 const vo::OdometryOptions& vo_options, const RunOptions& run_options,
                 RunSummary* summary, EvalInfo* info, std::string* error) {
  StereoSequence sequence;
  return OpenDataset(dir, options, &sequence, info, error) &&
         RunSequence(sequence, vo_options, run_options, summary, error);
}

}  // namespace harness
