// Trajectory files on disk: TUM (`t tx ty tz qx qy qz qw`, what evo and the TUM RGB-D tools
// read), KITTI odometry poses (12 numbers per line, row-major 3x4 [R | t]) and KITTI
// times.txt, plus the time association of the TUM tools' associate.py.
//
// Errors: every function returns false and fills *error (when non-null) with
// "<file>:<line>: <what was expected>"; nothing throws across this API.
// Numbers are written with FormatDouble (shortest text that reads back to the same double), so
// a write -> read round trip is exact and identical input gives byte-identical files.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace harness {

// A pose at a time stamp. T_world_cam maps points from the camera frame (x right, y down,
// z forward) into the trajectory's reference frame, called "world" here: whatever frame the
// file's poses are expressed in (for a KITTI poses.txt that is the first left camera).
struct StampedPose {
  double time_s = 0.0;                                            // time stamp (seconds)
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();  // p_world = T_world_cam * p_cam
};

// --- TUM: one pose per line, `t tx ty tz qx qy qz qw` (seconds, metres, unit quaternion with
// qw >= 0 as written). '#' comment lines and blank lines are skipped when reading; fields may be
// separated by spaces, tabs or commas. The quaternion read is normalised; a quaternion whose norm
// is off by more than kTumQuaternionNormTolerance is an error.
constexpr double kTumQuaternionNormTolerance = 1e-3;  // files with 6 printed digits pass
bool WriteTum(const std::string& path, const std::vector<StampedPose>& poses, std::string* error);
bool ReadTum(const std::string& path, std::vector<StampedPose>* poses, std::string* error);

// --- KITTI poses: one pose per line, the 12 numbers of the 3x4 matrix [R | t] row by row.
// Reading skips '#' comments and blank lines and checks that R is a rotation to within
// kKittiRotationTolerance (max |R^T R - I| entry); the values are kept as read.
constexpr double kKittiRotationTolerance = 1e-4;  // the KITTI ground truth prints 7 digits
bool WriteKittiPoses(const std::string& path, const std::vector<Eigen::Isometry3d>& poses,
                     std::string* error);
bool ReadKittiPoses(const std::string& path, std::vector<Eigen::Isometry3d>* poses,
                    std::string* error);

// --- KITTI times.txt: one time stamp (seconds) per line. Reading skips blank lines.
bool WriteKittiTimes(const std::string& path, const std::vector<double>& times_s,
                     std::string* error);
bool ReadKittiTimes(const std::string& path, std::vector<double>* times_s, std::string* error);

// --- Time association (TUM RGB-D benchmark tools, associate.py): every pair (a, b) with
// |a - (b + offset_s)| < max_difference_s is a candidate; candidates are taken greedily by
// increasing |difference| (ties: smaller a, then smaller b), each stamp used at most once; the
// result is sorted by the first stamp. Used to pair estimates with ground truth recorded at a
// different rate.
struct AssociateOptions {
  double max_difference_s = 0.02;  // largest |t_first - (t_second + offset_s)| kept (seconds), > 0;
                                   // associate.py's default
  double offset_s = 0.0;           // added to the second stream's stamps (seconds)

  bool IsValid(std::string* error) const;
};

struct AssociatedPair {
  std::size_t first = 0;   // index into the first stream
  std::size_t second = 0;  // index into the second stream
};

// Stamps need not be sorted. Returns the pairs sorted by the first stream's stamp.
// Aborts on invalid options (a programmer error).
std::vector<AssociatedPair> AssociateStamps(const std::vector<double>& first_s,
                                            const std::vector<double>& second_s,
                                            const AssociateOptions& options = {});
// Convenience over poses: fills the matched subsequences of both (same length, same order).
// Either output may be null.
std::vector<AssociatedPair> AssociatePoses(const std::vector<StampedPose>& first,
                                           const std::vector<StampedPose>& second,
                                           const AssociateOptions& options,
                                           std::vector<StampedPose>* first_matched,
                                           std::vector<StampedPose>* second_matched);

// --- Text helpers shared by the trajectory and dataset files.
// Shortest decimal text that parses back to exactly `value` ("0.1", "1e-05", "nan", "inf").
std::string FormatDouble(double value);
// Parses the whole of `text` as a double (no leading/trailing characters). Locale-independent.
// Accepts "nan"/"inf"; callers check finiteness where it matters.
bool ParseDouble(std::string_view text, double* value);
// Parses exactly `count` finite numbers separated by spaces, tabs or commas from `text`; on
// failure fills *what (when non-null) with what was wrong, e.g. "expected 12 numbers, got 11".
bool ParseNumbers(std::string_view text, std::size_t count, std::vector<double>* values,
                  std::string* what);
// Reads a text file into lines (without the line ends; "\r\n" accepted). Error names the file.
bool ReadTextLines(const std::string& path, std::vector<std::string>* lines, std::string* error);
// Writes `size` bytes to `path` (replacing the file). On failure the file is removed (nothing
// is left half-written) and the error names the file and the system's reason ("No space left
// on device").
bool WriteFileBytes(const std::string& path, const void* data, std::size_t size,
                    std::string* error);
// WriteFileBytes of a text.
bool WriteTextFile(const std::string& path, const std::string& text, std::string* error);

// True for a line that is empty, blank, or whose first non-blank character is '#'.
bool IsBlankOrComment(std::string_view line);

// The order check of every reader of time stamps (times.txt, TUM trajectories and image lists,
// EuRoC data.csv files): each stamp must be later than the one before. T is double (seconds)
// or int64_t (nanoseconds). Next() fails with
//   "PATH:LINE: time stamp 0.3 is not after the previous one, 0.4 (line 4); expected strictly
//    increasing time stamps"
template <typename T>
class IncreasingStamps {
 public:
  explicit IncreasingStamps(std::string path) : path_(std::move(path)) {}
  // `text` is the stamp as written (for the message); `line` is 1-based.
  bool Next(T stamp, std::string_view text, int line, std::string* error) {
    if (previous_line_ > 0 && !(stamp > previous_)) {
      if (error)
        *error = path_ + ":" + std::to_string(line) + ": time stamp " + std::string(text) +
                 (stamp == previous_ ? " repeats" : " is before") + " the previous one, " +
                 previous_text_ + " (line " + std::to_string(previous_line_) +
                 "); expected strictly increasing time stamps";
      return false;
    }
    previous_ = stamp;
    previous_text_ = std::string(text);
    previous_line_ = line;
    return true;
  }

 private:
  std::string path_;
  T previous_{};
  std::string previous_text_;
  int previous_line_ = 0;
};
// Unit quaternion of a rotation, sign fixed so that w >= 0 (deterministic output).
Eigen::Quaterniond CanonicalQuaternion(const Eigen::Matrix3d& R);

}  // namespace harness
