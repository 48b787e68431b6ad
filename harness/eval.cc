#include "harness/eval.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <vector>

#include "harness/trajectory_io.h"

namespace harness {
namespace {

namespace fs = std::filesystem;

bool Fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

int ExpectedFrames(size_t dataset_frames, const RunOptions& options) {
  const size_t n = options.max_frames > 0
                       ? std::min(dataset_frames, static_cast<size_t>(options.max_frames))
                       : dataset_frames;
  return static_cast<int>(n);
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

bool EvalKitti(const std::string& dir, const EvalOptions& options,
               const vo::OdometryOptions& vo_options, const RunOptions& run_options,
               RunSummary* summary, EvalInfo* info, std::string* error) {
  // --gt in the KITTI poses format (12 numbers per line, one per frame, the KITTI benchmark's
  // poses/NN.txt) goes to the reader; a TUM trajectory is associated by stamp below.
  const bool kitti_poses = !options.gt_path.empty() && FirstLineFields(options.gt_path) == 12;
  KittiReader reader;
  KittiReader::Options reader_options;
  if (kitti_poses) reader_options.poses_path = options.gt_path;
  if (!reader.Open(dir, reader_options, error)) return false;
  info->dataset_frames = reader.size();
  info->camera = reader.camera();
  // --gt: a TUM trajectory of the left camera, associated by stamp; replaces poses.txt.
  std::vector<StampedPose> external;
  std::vector<long> gt_index;
  if (kitti_poses) {
    info->ground_truth_path = options.gt_path;
    info->ground_truth_frames = reader.size();
  } else if (!options.gt_path.empty()) {
    if (!ReadTum(options.gt_path, &external, error)) return false;
    gt_index = AssociateGroundTruth(reader.times_s(), external, info->max_difference_s);
    info->ground_truth_frames =
        std::count_if(gt_index.begin(), gt_index.end(), [](long i) { return i >= 0; });
    if (info->ground_truth_frames == 0)
      return Fail(error, options.gt_path + ": no ground-truth pose within " +
                             FormatDouble(info->max_difference_s) + " s of any of the " +
                             std::to_string(reader.size()) + " frames in " + dir +
                             "/times.txt: a different clock or the wrong file?");
    info->ground_truth_path = options.gt_path;
  } else if (reader.has_ground_truth()) {
    info->ground_truth_path = (fs::path(dir) / "poses.txt").string();
    info->ground_truth_frames = reader.size();
  }
  size_t next = 0;
  FrameSource source = [&](DatasetFrame* frame, std::string* err) {
    if (next >= reader.size()) return false;
    const size_t i = next++;
    if (!reader.ReadFrame(i, frame, err)) return false;
    if (!gt_index.empty()) {
      frame->has_gt = gt_index[i] >= 0;
      frame->T_world_cam0 =
          frame->has_gt ? external[gt_index[i]].T_world_cam : Eigen::Isometry3d::Identity();
    }
    return true;
  };
  return RunOdometry(DatasetName(dir), reader.camera(), source,
                     ExpectedFrames(reader.size(), run_options), vo_options, run_options, "",
                     summary, error);
}

bool EvalEuroc(const std::string& dir, const EvalOptions& options,
               const vo::OdometryOptions& vo_options, const RunOptions& run_options,
               RunSummary* summary, EvalInfo* info, std::string* error) {
  EurocReader reader;
  EurocReader::Options reader_options;
  reader_options.gt_path = options.gt_path;
  reader_options.gt_max_difference_s = info->max_difference_s;
  if (!reader.Open(dir, reader_options, error)) return false;
  StereoRectification rectification;
  if (!reader.Rectification(options.rectification, &rectification, error)) return false;
  info->dataset_frames = reader.size();
  info->unpaired_frames = reader.unpaired_frames();
  info->ground_truth_path = reader.ground_truth_path();
  info->ground_truth_frames = reader.ground_truth_frames();
  info->rectified = !rectification.IsIdentity();
  info->camera = rectification.camera;
  size_t next = 0;
  FrameSource source = [&](DatasetFrame* frame, std::string* err) {
    if (next >= reader.size()) return false;
    if (!reader.ReadFrame(next++, frame, err)) return false;
    RectifyFrame(rectification, frame);
    return true;
  };
  return RunOdometry(DatasetName(dir), rectification.camera, source,
                     ExpectedFrames(reader.size(), run_options), vo_options, run_options, "",
                     summary, error);
}

bool EvalTum(const std::string& dir, const EvalOptions& options,
             const vo::OdometryOptions& vo_options, const RunOptions& run_options,
             RunSummary* summary, EvalInfo* info, std::string* error) {
  TumReader reader;
  TumReader::Options reader_options;
  reader_options.gt_path = options.gt_path;
  reader_options.gt_max_difference_s = info->max_difference_s;
  if (!reader.Open(dir, reader_options, error)) return false;
  info->dataset_frames = reader.size();
  info->unpaired_frames = reader.unpaired_frames();
  info->ground_truth_path = reader.ground_truth_path();
  info->ground_truth_frames = reader.ground_truth_frames();
  info->camera = reader.camera();
  size_t next = 0;
  FrameSource source = [&](DatasetFrame* frame, std::string* err) {
    if (next >= reader.size()) return false;
    return reader.ReadFrame(next++, frame, err);
  };
  return RunOdometry(DatasetName(dir), reader.camera(), source,
                     ExpectedFrames(reader.size(), run_options), vo_options, run_options, "",
                     summary, error);
}

}  // namespace

bool EvalOptions::IsValid(std::string* error) const {
  if (format != DatasetFormat::kKitti && format != DatasetFormat::kEuroc &&
      format != DatasetFormat::kTum)
    return Fail(error, "format must be kitti, euroc or tum");
  if (!std::isfinite(max_difference_s) || max_difference_s < 0.0)
    return Fail(error, "max difference must be finite and >= 0 (0 = the format's default), got " +
                           FormatDouble(max_difference_s));
  return rectification.IsValid(error);
}

double DefaultMaxDifference(DatasetFormat format) {
  return format == DatasetFormat::kEuroc ? EurocReader::Options().gt_max_difference_s
                                         : TumReader::Options().gt_max_difference_s;
}

std::string DatasetName(const std::string& dir) {
  fs::path p = fs::path(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // "seq/" -> "seq"
  const std::string name = p.filename().string();
  return name.empty() || name == "." || name == ".." ? "dataset" : name;
}

bool EvalDataset(const std::string& dir, const EvalOptions& options,
                 const vo::OdometryOptions& vo_options, const RunOptions& run_options,
                 RunSummary* summary, EvalInfo* info, std::string* error) {
  std::string why;
  if (!options.IsValid(&why)) return Fail(error, "eval options: " + why);
  *info = EvalInfo();
  info->max_difference_s = options.max_difference_s > 0.0 ? options.max_difference_s
                                                          : DefaultMaxDifference(options.format);
  switch (options.format) {
    case DatasetFormat::kKitti:
      return EvalKitti(dir, options, vo_options, run_options, summary, info, error);
    case DatasetFormat::kEuroc:
      return EvalEuroc(dir, options, vo_options, run_options, summary, info, error);
    case DatasetFormat::kTum:
      return EvalTum(dir, options, vo_options, run_options, summary, info, error);
  }
  return Fail(error, "unknown dataset format");
}

}  // namespace harness
