#include "harness/dataset/euroc_imu.h"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <functional>

#include "harness/dataset/common.h"
#include "harness/dataset/internal.h"
#include "harness/trajectory_io.h"
#include "sim/yaml_input.h"

namespace harness {
namespace {

using dataset_internal::Fail;
using dataset_internal::Join;
using dataset_internal::Where;

constexpr const char* kImuHeader =
    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
    "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]";
// As EuRoC's (and DatasetWriter's frame-rate ground truth).
constexpr const char* kGroundTruthHeader =
    "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
    "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
    "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
    "b_a_RS_S_z [m s^-2]";
constexpr const char* kIdentityTbs =
    "T_BS:\n  cols: 4\n  rows: 4\n  data: [1.0, 0.0, 0.0, 0.0,\n         0.0, 1.0, 0.0, 0.0,\n"
    "         0.0, 0.0, 1.0, 0.0,\n         0.0, 0.0, 0.0, 1.0]\n";

bool MakeDir(const std::string& path, std::string* error) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec) return Fail(error, path + ": cannot create folder: " + ec.message());
  return true;
}

bool ParseStamp(std::string_view text, int64_t* value) {
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  if (text.empty()) return false;
  const std::from_chars_result r = std::from_chars(text.data(), text.data() + text.size(), *value);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

// Reads the data rows of a EuRoC CSV whose lines are "<timestamp ns>,<fields>" (comments and
// blank lines skipped) and calls row(line_no, stamp, its text, the numbers after it) for each;
// a row without a stamp before its first comma, or without `fields` numbers after it, is
// refused at file:line (`layout` names the line's fields, `numbers` those after the stamp).
bool ForEachStampedRow(
    const std::string& path, size_t fields, const std::string& layout, const std::string& numbers,
    const std::function<bool(int, int64_t, std::string_view, const std::vector<double>&)>& row,
    std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) return false;
  std::vector<double> v;
  std::string what;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsBlankOrComment(lines[i])) continue;
    const int line_no = static_cast<int>(i) + 1;
    const std::string_view line(lines[i]);
    const size_t comma = line.find(',');
    int64_t stamp = 0;
    if (comma == std::string_view::npos || !ParseStamp(line.substr(0, comma), &stamp))
      return Fail(error, Where(path, line_no) + "expected '" + layout + "' (" +
                             std::to_string(fields + 1) + " fields)");
    if (!ParseNumbers(line.substr(comma + 1), fields, &v, &what))
      return Fail(error, Where(path, line_no) + what + " after the time stamp (" + numbers + ")");
    if (!row(line_no, stamp, line.substr(0, comma), v)) return false;
  }
  return true;
}

}  // namespace

Eigen::Isometry3d CameraInImuFrame(const Eigen::Isometry3d& T_body_cam,
                                   const Eigen::Isometry3d& T_body_imu) {
  return T_body_imu.inverse() * T_body_cam;
}

bool WriteEurocImu(const std::string& mav0, const std::vector<sim::ImuSample>& samples,
                   const sim::ImuOptions& imu, int64_t stamp_offset_ns, bool* wrote_ground_truth,
                   std::string* error) {
  *wrote_ground_truth = false;
  std::string data = std::string(kImuHeader) + "\n", gt = std::string(kGroundTruthHeader) + "\n";
  bool has_gt = !samples.empty();
  for (size_t i = 0; i < samples.size(); ++i) {
    const sim::ImuSample& s = samples[i];
    if (i > 0 && !(TimeToNs(s.time_s) > TimeToNs(samples[i - 1].time_s)))
      return Fail(error, Join(mav0, "imu0/data.csv") + ": IMU sample " + std::to_string(i) +
                             " at " + FormatDouble(s.time_s) +
                             " s is not after the previous one; expected increasing times");
    const std::string stamp = std::to_string(stamp_offset_ns + TimeToNs(s.time_s));
    data += stamp;
    for (double x : {s.gyro_radps.x(), s.gyro_radps.y(), s.gyro_radps.z(), s.accel_mps2.x(),
                     s.accel_mps2.y(), s.accel_mps2.z()})
      data += "," + FormatDouble(x);
    data += "\n";
    has_gt = has_gt && s.has_gt;
    if (!has_gt) continue;
    const Eigen::Vector3d p = s.T_world_imu.translation();
    const Eigen::Quaterniond q = CanonicalQuaternion(s.T_world_imu.linear());
    gt += stamp;
    for (double x :
         {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), s.v_world_mps.x(), s.v_world_mps.y(),
          s.v_world_mps.z(), s.gyro_bias_radps.x(), s.gyro_bias_radps.y(), s.gyro_bias_radps.z(),
          s.accel_bias_mps2.x(), s.accel_bias_mps2.y(), s.accel_bias_mps2.z()})
      gt += "," + FormatDouble(x);
    gt += "\n";
  }
  const std::string yaml =
      "%YAML:1.0\n# IMU sensor definitions.\nsensor_type: imu\ncomment: vobench simulated IMU "
      "(MuJoCo gyro and accelerometer, sim/imu.h noise model)\n\n"
      "# Sensor extrinsics wrt. the body-frame (the body frame is the IMU's).\n" +
      std::string(kIdentityTbs) + "rate_hz: " + FormatDouble(imu.rate_hz) +
      "\n\n# inertial sensor noise model parameters (static)\n"
      "gyroscope_noise_density: " +
      FormatDouble(imu.gyro_noise_density) +
      "     # [ rad / s / sqrt(Hz) ]   ( gyro \"white noise\" )\n"
      "gyroscope_random_walk: " +
      FormatDouble(imu.gyro_random_walk) +
      "       # [ rad / s^2 / sqrt(Hz) ] ( gyro bias diffusion )\n"
      "accelerometer_noise_density: " +
      FormatDouble(imu.accel_noise_density) +
      "  # [ m / s^2 / sqrt(Hz) ]   ( accel \"white noise\" )\n"
      "accelerometer_random_walk: " +
      FormatDouble(imu.accel_random_walk) +
      "    # [ m / s^3 / sqrt(Hz) ]  ( accel bias diffusion )\n";
  if (!MakeDir(Join(mav0, "imu0"), error) ||
      !WriteTextFile(Join(mav0, "imu0/data.csv"), data, error) ||
      !WriteTextFile(Join(mav0, "imu0/sensor.yaml"), yaml, error) ||
      !WriteTextFile(Join(mav0, "body.yaml"),
                     "%YAML:1.0\n# The body frame is the IMU's (imu0, T_BS identity).\n"
                     "comment: vobench simulated robot, body frame = imu0\n",
                     error))
    return false;
  if (!has_gt) return true;
  *wrote_ground_truth = true;
  const std::string gt_dir = Join(mav0, "state_groundtruth_estimate0");
  return MakeDir(gt_dir, error) && WriteTextFile(Join(gt_dir, "data.csv"), gt, error) &&
         WriteTextFile(Join(gt_dir, "sensor.yaml"),
                       "%YAML:1.0\n# Ground truth of the body (= imu0) frame: the simulator's.\n"
                       "sensor_type: visual-inertial\ncomment: vobench simulator ground truth "
                       "(pose, velocity and the IMU's true biases at every IMU sample)\n\n"
                       "# Sensor extrinsics wrt. the body-frame.\n" +
                           std::string(kIdentityTbs),
                       error);
}

bool ReadEurocImu(const std::string& path, std::vector<int64_t>* t_ns,
                  std::vector<sim::ImuSample>* samples, std::string* error) {
  t_ns->clear();
  samples->clear();
  IncreasingStamps<int64_t> order(path);
  const auto row = [&](int line_no, int64_t stamp, std::string_view text,
                       const std::vector<double>& v) {
    if (!order.Next(stamp, text, line_no, error)) return false;
    sim::ImuSample s;
    s.time_s = dataset_internal::NsToSeconds(stamp);
    s.gyro_radps = Eigen::Vector3d(v[0], v[1], v[2]);
    s.accel_mps2 = Eigen::Vector3d(v[3], v[4], v[5]);
    t_ns->push_back(stamp);
    samples->push_back(s);
    return true;
  };
  if (!ForEachStampedRow(path, 6, "<timestamp ns>,w_x,w_y,w_z,a_x,a_y,a_z",
                         "w_RS_S xyz [rad s^-1], a_RS_S xyz [m s^-2]", row, error))
    return false;
  if (samples->empty()) return Fail(error, path + ": no IMU samples");
  return true;
}

bool ReadEurocImuGroundTruth(const std::string& path, const std::vector<int64_t>& t_ns,
                             std::vector<sim::ImuSample>* samples, std::string* error) {
  if (samples->size() != t_ns.size())
    return Fail(error, path + ": ReadEurocImuGroundTruth: " + std::to_string(t_ns.size()) +
                           " stamps for " + std::to_string(samples->size()) + " samples");
  size_t next = 0;  // the sample the next line is for
  const auto row = [&](int line_no, int64_t stamp, std::string_view, const std::vector<double>& v) {
    if (next >= t_ns.size() || stamp != t_ns[next])
      return Fail(error,
                  Where(path, line_no) + "time stamp " + std::to_string(stamp) +
                      (next < t_ns.size() ? " is not the IMU sample's " + std::to_string(t_ns[next])
                                          : " is past the last IMU sample's") +
                      " (expected one line per imu0 sample, at its stamp)");
    Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (!(q.norm() > 0.5 && q.norm() < 2.0))
      return Fail(error, Where(path, line_no) + "the quaternion (fields 5-8) is not a rotation");
    sim::ImuSample& s = (*samples)[next++];
    s.has_gt = true;
    s.T_world_imu.linear() = q.normalized().toRotationMatrix();
    s.T_world_imu.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    s.v_world_mps = Eigen::Vector3d(v[7], v[8], v[9]);
    s.gyro_bias_radps = Eigen::Vector3d(v[10], v[11], v[12]);
    s.accel_bias_mps2 = Eigen::Vector3d(v[13], v[14], v[15]);
    return true;
  };
  if (!ForEachStampedRow(path, 16, "<timestamp ns>,p xyz,q wxyz,v xyz,b_w xyz,b_a xyz",
                         "p xyz, q wxyz, v xyz, b_w xyz, b_a xyz", row, error))
    return false;
  if (next != t_ns.size())
    return Fail(error, path + ": " + std::to_string(next) + " lines for " +
                           std::to_string(t_ns.size()) +
                           " IMU samples (expected one line per imu0 sample)");
  return true;
}

bool ReadEurocImuSensorYaml(const std::string& path, sim::ImuOptions* imu, std::string* error) {
  std::vector<std::string> lines;
  if (!ReadTextLines(path, &lines, error)) return false;
  std::string text;  // OpenCV's "%YAML:1.0", which yaml-cpp rejects, as an empty line
  for (size_t i = 0; i < lines.size(); ++i)
    text += (i == 0 && lines[i].rfind("%YAML:", 0) == 0 ? std::string() : lines[i]) + "\n";
  sim::YamlReader r(path);
  if (!r.Parse(text)) return r.Report(error);
  YAML::Node root = r.root();  // not const: a missing key reads as undefined, not invalid
  if (!r.ExpectMap(root, "", "a mapping (rate_hz, gyroscope_noise_density, ...)"))
    return r.Report(error);
  sim::ImuOptions o = *imu;
  const std::pair<const char*, double*> keys[] = {
      {"rate_hz", &o.rate_hz},
      {"gyroscope_noise_density", &o.gyro_noise_density},
      {"gyroscope_random_walk", &o.gyro_random_walk},
      {"accelerometer_noise_density", &o.accel_noise_density},
      {"accelerometer_random_walk", &o.accel_random_walk}};
  for (const auto& [key, value] : keys) {
    if (!r.Require(root, "", key, "a number") || !r.ReadDouble(root[key], key, value) ||
        !r.Check(*value > 0.0 || (*value == 0.0 && key != keys[0].first), root, "", key,
                 std::string(key == keys[0].first ? "expected > 0 Hz" : "expected >= 0") +
                     ", got " + FormatDouble(*value)))
      return r.Report(error);
  }
  *imu = o;
  return true;
}

void ImuSamplesBetween(const std::vector<int64_t>& t_ns, const std::vector<sim::ImuSample>& samples,
                       int64_t after_ns, int64_t up_to_ns, std::vector<sim::ImuSample>* out) {
  const auto begin = std::upper_bound(t_ns.begin(), t_ns.end(), after_ns);
  const auto end = std::upper_bound(t_ns.begin(), t_ns.end(), up_to_ns);
  for (auto it = begin; it < end; ++it) out->push_back(samples[it - t_ns.begin()]);
}

}  // namespace harness
