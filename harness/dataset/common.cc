#include "harness/dataset/common.h"

#include <cmath>

namespace harness {

bool ParseDatasetFormat(const std::string& name, DatasetFormat* format) {
  if (name == "kitti")
    *format = DatasetFormat::kKitti;
  else if (name == "euroc")
    *format = DatasetFormat::kEuroc;
  else if (name == "tum")
    *format = DatasetFormat::kTum;
  else if (name == "rosbag")
    *format = DatasetFormat::kRosbag;
  else
    return false;
  return true;
}

const char* DatasetFormatName(DatasetFormat format) {
  switch (format) {
    case DatasetFormat::kKitti:
      return "kitti";
    case DatasetFormat::kEuroc:
      return "euroc";
    case DatasetFormat::kTum:
      return "tum";
    case DatasetFormat::kRosbag:
      return "rosbag";
  }
  return "unknown";
}

int64_t TimeToNs(double time_s) { return std::llround(time_s * 1e9); }

std::vector<long> AssociateGroundTruth(const std::vector<double>& frame_times_s,
                                       const std::vector<StampedPose>& ground_truth,
                                       double max_difference_s) {
  std::vector<long> index(frame_times_s.size(), -1);
  if (frame_times_s.empty() || ground_truth.empty()) return index;
  const double t0 = frame_times_s.front();
  std::vector<double> frame_s, gt_s;
  for (double t : frame_times_s) frame_s.push_back(t - t0);
  for (const StampedPose& p : ground_truth) gt_s.push_back(p.time_s - t0);
  AssociateOptions assoc;
  assoc.max_difference_s = max_difference_s;
  for (const AssociatedPair& p : AssociateStamps(frame_s, gt_s, assoc))
    index[p.first] = static_cast<long>(p.second);
  return index;
}

}  // namespace harness
