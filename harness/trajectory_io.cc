#include "harness/trajectory_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <tuple>

namespace harness {
namespace {

void SetError(std::string* error, const std::string& message) {
  if (error) *error = message;
}

std::string Where(const std::string& path, int line) {
  return path + ":" + std::to_string(line) + ": ";
}

}  // namespace

bool ReadTextLines(const std::string& path, std::vector<std::string>* lines, std::string* error) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    SetError(error, path + ": file not found");
    return false;
  }
  if (std::filesystem::is_directory(path, ec)) {
    SetError(error, path + ": is a folder, expected a text file");
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    SetError(error, path + ": cannot open for reading");
    return false;
  }
  lines->clear();
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines->push_back(line);
  }
  if (in.bad()) {
    SetError(error, path + ": read error");
    return false;
  }
  return true;
}

bool WriteFileBytes(const std::string& path, const void* data, std::size_t size,
                    std::string* error) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    SetError(error, path + ": cannot open for writing: " + std::strerror(errno));
    return false;
  }
  const char* p = static_cast<const char*>(data);
  std::size_t left = size;
  int write_errno = 0;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      write_errno = n < 0 ? errno : EIO;
      break;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  struct stat st = {};
  const bool regular = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  // close() reports a delayed write error (NFS, quotas): a file is written only when it says so.
  if (::close(fd) != 0 && write_errno == 0) write_errno = errno;
  if (write_errno != 0) {
    if (regular) ::unlink(path.c_str());  // nothing written half-way (never a device: /dev/full)
    SetError(error, path + ": cannot write: " + std::strerror(write_errno));
    return false;
  }
  return true;
}

bool WriteTextFile(const std::string& path, const std::string& text, std::string* error) {
  return WriteFileBytes(path, text.data(), text.size(), error);
}

bool IsBlankOrComment(std::string_view line) {
  const size_t first = line.find_first_not_of(" \t");
  return first == std::string::npos || line[first] == '#';
}

namespace {

// Splits on spaces, tabs and commas (associate.py does the same).
std::vector<std::string_view> SplitFields(std::string_view s) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == ',')) ++i;
    const size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != ',') ++i;
    if (i > start) fields.push_back(s.substr(start, i - start));
  }
  return fields;
}

}  // namespace

bool ParseNumbers(std::string_view text, size_t n, std::vector<double>* values, std::string* what) {
  std::string scratch;
  if (!what) what = &scratch;
  const std::vector<std::string_view> fields = SplitFields(text);
  if (fields.size() != n) {
    *what = "expected " + std::to_string(n) + " numbers, got " + std::to_string(fields.size()) +
            " fields";
    return false;
  }
  values->resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (!ParseDouble(fields[i], &(*values)[i])) {
      *what =
          "field " + std::to_string(i + 1) + " ('" + std::string(fields[i]) + "') is not a number";
      return false;
    }
    if (!std::isfinite((*values)[i])) {
      *what =
          "field " + std::to_string(i + 1) + " ('" + std::string(fields[i]) + "') is not finite";
      return false;
    }
  }
  return true;
}

namespace {

std::string KittiRow(const Eigen::Isometry3d& T) {
  std::string row;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (!row.empty()) row += ' ';
      row += FormatDouble(T.matrix()(r, c));
    }
  }
  return row;
}

bool IsFinite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

}  // namespace

std::string FormatDouble(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (value == 0.0) return "0";  // also for -0.0: one spelling for zero
  char buffer[64];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, r.ptr);
}

bool ParseDouble(std::string_view text, double* value) {
  if (text.empty()) return false;
  // from_chars rejects a leading '+', which some writers emit.
  if (text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return false;
  const std::from_chars_result r = std::from_chars(text.data(), text.data() + text.size(), *value);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

Eigen::Quaterniond CanonicalQuaternion(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return q;
}

// ---------------------------------------------------------------------------------------------
// TUM

bool WriteTum(const std::string& path, const std::vector<StampedPose>& poses, std::string* error) {
  std::string text;
  for (size_t i = 0; i < poses.size(); ++i) {
    const StampedPose& p = poses[i];
    if (!std::isfinite(p.time_s) || !IsFinite(p.T_world_cam)) {
      SetError(error, path + ": pose " + std::to_string(i) + " has a non-finite time or pose");
      return false;
    }
    const Eigen::Vector3d t = p.T_world_cam.translation();
    const Eigen::Quaterniond q = CanonicalQuaternion(p.T_world_cam.linear());
    text += FormatDouble(p.time_s) + ' ' + FormatDouble(t.x()) + ' ' + FormatDouble(t.y()) + ' ' +
            FormatDouble(t.z()) + ' ' + FormatDouble(q.x()) + ' ' + FormatDouble(q.y()) + ' ' +
            FormatDouble(q.z()) + ' ' + FormatDouble(q.w()) + '\n';
  }
  return WriteTextFile(path, text, error);
}

namespace {

// A position farther than this from the origin is no robot's (1000 km: a GPS/INS drive in a
// local frame stays far inside; 1e300 m would turn every metric into inf or 0).
constexpr double kMaxPositionM = 1e6;

bool PositionIsPlausible(const Eigen::Vector3d& t, const std::string& path, int line_no,
                         std::string* error) {
  if (t.stableNorm() <= kMaxPositionM) return true;  // stable: 1e300 does not overflow to inf
  SetError(error, Where(path, line_no) + "position " + FormatDouble(t.stableNorm()) +
                      " m from the origin is beyond " + FormatDouble(kMaxPositionM) +
                      " m (1000 km): not a trajectory a VO can be measured on");
  return false;
}

}  // namespace

bool ReadTum(const std::string& path, std::vector<StampedPose>* poses, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) return false;
  std::vector<StampedPose> out;
  std::vector<double> v;
  std::string what;
  IncreasingStamps<double> order(path);
  for (size_t i = 0; i < lines.size(); ++i) {
    const int line_no = static_cast<int>(i) + 1;
    if (IsBlankOrComment(lines[i])) continue;
    if (!ParseNumbers(lines[i], 8, &v, &what)) {
      SetError(error, Where(path, line_no) + what + " (TUM row: t tx ty tz qx qy qz qw)");
      return false;
    }
    if (!order.Next(v[0], SplitFields(lines[i])[0], line_no, error)) return false;
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);  // (w, x, y, z)
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > kTumQuaternionNormTolerance) {
      SetError(error, Where(path, line_no) + "expected a unit quaternion (qx qy qz qw), norm is " +
                          FormatDouble(norm));
      return false;
    }
    if (!PositionIsPlausible(Eigen::Vector3d(v[1], v[2], v[3]), path, line_no, error)) return false;
    q.normalize();
    StampedPose p;
    p.time_s = v[0];
    p.T_world_cam.setIdentity();
    p.T_world_cam.linear() = q.toRotationMatrix();
    p.T_world_cam.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    out.push_back(p);
  }
  *poses = std::move(out);
  return true;
}

// ---------------------------------------------------------------------------------------------
// KITTI

bool WriteKittiPoses(const std::string& path, const std::vector<Eigen::Isometry3d>& poses,
                     std::string* error) {
  std::string text;
  for (size_t i = 0; i < poses.size(); ++i) {
    if (!IsFinite(poses[i])) {
      SetError(error, path + ": pose " + std::to_string(i) + " is not finite");
      return false;
    }
    text += KittiRow(poses[i]) + '\n';
  }
  return WriteTextFile(path, text, error);
}

bool ReadKittiPoses(const std::string& path, std::vector<Eigen::Isometry3d>* poses,
                    std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) return false;
  std::vector<Eigen::Isometry3d> out;
  std::vector<double> v;
  std::string what;
  for (size_t i = 0; i < lines.size(); ++i) {
    const int line_no = static_cast<int>(i) + 1;
    if (IsBlankOrComment(lines[i])) continue;
    if (!ParseNumbers(lines[i], 12, &v, &what)) {
      SetError(error, Where(path, line_no) + what + " (KITTI row: 3x4 matrix [R | t], row-major)");
      return false;
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) T.matrix()(r, c) = v[4 * r + c];
    const Eigen::Matrix3d R = T.linear();
    const double orth_err = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (orth_err > kKittiRotationTolerance || R.determinant() < 0.0) {
      SetError(error,
               Where(path, line_no) + "expected a rotation in the first 3 columns (|R^T R - I| = " +
                   FormatDouble(orth_err) + ", det = " + FormatDouble(R.determinant()) + ")");
      return false;
    }
    if (!PositionIsPlausible(T.translation(), path, line_no, error)) return false;
    out.push_back(T);
  }
  *poses = std::move(out);
  return true;
}

bool WriteKittiTimes(const std::string& path, const std::vector<double>& times_s,
                     std::string* error) {
  std::string text;
  for (size_t i = 0; i < times_s.size(); ++i) {
    if (!std::isfinite(times_s[i])) {
      SetError(error, path + ": time " + std::to_string(i) + " is not finite");
      return false;
    }
    text += FormatDouble(times_s[i]) + '\n';
  }
  return WriteTextFile(path, text, error);
}

bool ReadKittiTimes(const std::string& path, std::vector<double>* times_s, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) return false;
  IncreasingStamps<double> order(path);
  std::vector<double> out;
  std::vector<double> v;
  std::string what;
  for (size_t i = 0; i < lines.size(); ++i) {
    const int line_no = static_cast<int>(i) + 1;
    if (IsBlankOrComment(lines[i])) continue;
    if (!ParseNumbers(lines[i], 1, &v, &what)) {
      SetError(error, Where(path, line_no) + what + " (one time stamp in seconds per line)");
      return false;
    }
    if (!order.Next(v[0], SplitFields(lines[i])[0], line_no, error)) return false;
    out.push_back(v[0]);
  }
  *times_s = std::move(out);
  return true;
}

// ---------------------------------------------------------------------------------------------
// Association (associate.py)

bool AssociateOptions::IsValid(std::string* error) const {
  if (!std::isfinite(max_difference_s) || max_difference_s <= 0.0) {
    SetError(error,
             "max_difference_s must be finite and > 0, got " + FormatDouble(max_difference_s));
    return false;
  }
  if (!std::isfinite(offset_s)) {
    SetError(error, "offset_s must be finite, got " + FormatDouble(offset_s));
    return false;
  }
  return true;
}

std::vector<AssociatedPair> AssociateStamps(const std::vector<double>& first_s,
                                            const std::vector<double>& second_s,
                                            const AssociateOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) {
    std::fprintf(stderr, "harness::AssociateStamps: invalid options: %s\n", why.c_str());
    std::abort();
  }
  // Second stream sorted by (shifted) stamp, so each first stamp looks only at its window.
  std::vector<std::pair<double, size_t>> second_sorted;
  second_sorted.reserve(second_s.size());
  for (size_t j = 0; j < second_s.size(); ++j)
    second_sorted.emplace_back(second_s[j] + options.offset_s, j);
  std::sort(second_sorted.begin(), second_sorted.end());

  // Candidates (|difference|, a, b, i, j): the tuple order is associate.py's tie-breaking.
  using Candidate = std::tuple<double, double, double, size_t, size_t>;
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < first_s.size(); ++i) {
    const double a = first_s[i];
    auto it = std::lower_bound(second_sorted.begin(), second_sorted.end(),
                               std::make_pair(a - options.max_difference_s, size_t{0}));
    for (; it != second_sorted.end() && it->first <= a + options.max_difference_s; ++it) {
      const double diff = std::abs(a - it->first);
      if (diff < options.max_difference_s)
        candidates.emplace_back(diff, a, second_s[it->second], i, it->second);
    }
  }
  std::sort(candidates.begin(), candidates.end());

  // Greedy: smallest difference first, each stamp used once.
  std::vector<bool> first_used(first_s.size(), false), second_used(second_s.size(), false);
  std::vector<std::tuple<double, double, size_t, size_t>> matches;
  for (const Candidate& c : candidates) {
    const size_t i = std::get<3>(c), j = std::get<4>(c);
    if (first_used[i] || second_used[j]) continue;
    first_used[i] = second_used[j] = true;
    matches.emplace_back(std::get<1>(c), std::get<2>(c), i, j);
  }
  std::sort(matches.begin(), matches.end());
  std::vector<AssociatedPair> pairs;
  pairs.reserve(matches.size());
  for (const auto& m : matches) pairs.push_back({std::get<2>(m), std::get<3>(m)});
  return pairs;
}

std::vector<AssociatedPair> AssociatePoses(const std::vector<StampedPose>& first,
                                           const std::vector<StampedPose>& second,
                                           const AssociateOptions& options,
                                           std::vector<StampedPose>* first_matched,
                                           std::vector<StampedPose>* second_matched) {
  std::vector<double> a, b;
  a.reserve(first.size());
  b.reserve(second.size());
  for (const StampedPose& p : first) a.push_back(p.time_s);
  for (const StampedPose& p : second) b.push_back(p.time_s);
  const std::vector<AssociatedPair> pairs = AssociateStamps(a, b, options);
  if (first_matched) first_matched->clear();
  if (second_matched) second_matched->clear();
  for (const AssociatedPair& pair : pairs) {
    if (first_matched) first_matched->push_back(first[pair.first]);
    if (second_matched) second_matched->push_back(second[pair.second]);
  }
  return pairs;
}

}  // namespace harness
