#include "harness/dataset/rosbag.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include "harness/dataset/euroc.h"
#include "harness/dataset/euroc_imu.h"
#include "harness/dataset/internal.h"
#include "harness/trajectory_io.h"

#ifdef VOBENCH_ROSBAG
#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <opencv2/imgproc.hpp>
#endif

namespace harness {

using dataset_internal::Fail;

bool RosbagSupported() {
#ifdef VOBENCH_ROSBAG
  return true;
#else
  return false;
#endif
}

std::string RosbagUnavailable() {
  return "this vobench was built without ROS bag support (CMake option VOBENCH_ROSBAG is OFF: "
         "install librosbag-dev libsensor-msgs-dev libgeometry-msgs-dev, as setup.sh does, and "
         "configure again)";
}

std::string RosbagPathInDataset(const std::string& dir) {
  const std::string normal = dataset_internal::NormalizeDir(dir);
  return dataset_internal::Join(normal, std::filesystem::path(normal).filename().string() + ".bag");
}

std::string CameraInfoTopic(const std::string& image_topic) {
  const size_t slash = image_topic.rfind('/');
  return (slash == std::string::npos ? std::string() : image_topic.substr(0, slash)) +
         "/camera_info";
}

#ifdef VOBENCH_ROSBAG
namespace {

constexpr const char* kLeftFrameId = "cam0";  // EuRoC's bags: cam0, cam1, imu4
constexpr const char* kRightFrameId = "cam1";
constexpr const char* kImuFrameId = "imu4";
constexpr const char* kWorldFrameId = "world";

ros::Time RosTime(int64_t stamp_ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(stamp_ns));
  return t;
}

int64_t StampNs(const ros::Time& t) { return static_cast<int64_t>(t.toNSec()); }

geometry_msgs::TransformStamped PoseMessage(int64_t stamp_ns, const char* child,
                                            const Eigen::Isometry3d& T_world_child) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = RosTime(stamp_ns);
  m.header.frame_id = kWorldFrameId;
  m.child_frame_id = child;
  const Eigen::Vector3d p = T_world_child.translation();
  const Eigen::Quaterniond q = CanonicalQuaternion(T_world_child.linear());
  m.transform.translation.x = p.x();
  m.transform.translation.y = p.y();
  m.transform.translation.z = p.z();
  m.transform.rotation.x = q.x();
  m.transform.rotation.y = q.y();
  m.transform.rotation.z = q.z();
  m.transform.rotation.w = q.w();
  return m;
}

}  // namespace

struct RosbagWriter::Impl {
  rosbag::Bag bag;
  bool open = false;
  std::string path;
  sensor_msgs::CameraInfo info[2];
  sensor_msgs::Imu imu;  // the covariances, filled once
};

RosbagWriter::RosbagWriter() : impl_(new Impl) {}
RosbagWriter::~RosbagWriter() {
  std::string ignored;
  Close(&ignored);
}

bool RosbagWriter::Open(const std::string& path, const vo::StereoCamera& camera,
                        const sim::ImuOptions& imu, std::string* error) {
  try {
    impl_->bag.open(path, rosbag::bagmode::Write);
  } catch (const std::exception& e) {
    return Fail(error, path + ": cannot write the bag: " + e.what());
  }
  impl_->open = true;
  impl_->path = path;
  for (int cam = 0; cam < 2; ++cam) {
    sensor_msgs::CameraInfo& c = impl_->info[cam];
    c.header.frame_id = cam == 0 ? kLeftFrameId : kRightFrameId;
    c.width = static_cast<uint32_t>(camera.width);
    c.height = static_cast<uint32_t>(camera.height);
    c.distortion_model = "plumb_bob";
    c.D.assign(5, 0.0);
    c.K = {camera.fx_px, 0, camera.cx_px, 0, camera.fy_px, camera.cy_px, 0, 0, 1};
    c.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    c.P = {camera.fx_px, 0, camera.cx_px, 0, 0, camera.fy_px, camera.cy_px, 0, 0, 0, 1, 0};
    if (cam == 1) c.P[3] = -(camera.fx_px * camera.baseline_m);  // as calib.txt's P1
  }
  // Discrete white noise of a continuous density sampled at rate_hz: sigma^2 = density^2 * rate.
  sensor_msgs::Imu& m = impl_->imu;
  m.header.frame_id = kImuFrameId;
  m.orientation_covariance[0] = -1.0;  // no orientation estimate (REP 145)
  const double gyro_var = imu.gyro_noise_density * imu.gyro_noise_density * imu.rate_hz;
  const double accel_var = imu.accel_noise_density * imu.accel_noise_density * imu.rate_hz;
  for (int i = 0; i < 3; ++i) {
    m.angular_velocity_covariance[4 * i] = gyro_var;
    m.linear_acceleration_covariance[4 * i] = accel_var;
  }
  return true;
}

bool RosbagWriter::Add(const DatasetFrame& frame, const cv::Mat& depth_mm, int64_t stamp_ns,
                       int64_t stamp_offset_ns, std::string* error) {
  if (!impl_->open) return Fail(error, "RosbagWriter::Add: bag is not open");
  try {
    const ros::Time stamp = RosTime(stamp_ns);
    // IMU samples first: those of (previous frame, this frame] precede the images in time.
    for (const sim::ImuSample& s : frame.imu) {
      const int64_t imu_ns = stamp_offset_ns + TimeToNs(s.time_s);
      sensor_msgs::Imu m = impl_->imu;
      m.header.stamp = RosTime(imu_ns);
      m.angular_velocity.x = s.gyro_radps.x();
      m.angular_velocity.y = s.gyro_radps.y();
      m.angular_velocity.z = s.gyro_radps.z();
      m.linear_acceleration.x = s.accel_mps2.x();
      m.linear_acceleration.y = s.accel_mps2.y();
      m.linear_acceleration.z = s.accel_mps2.z();
      const RosbagTopics topics;
      impl_->bag.write(topics.imu, m.header.stamp, m);
      if (s.has_gt)
        impl_->bag.write(topics.imu_ground_truth, m.header.stamp,
                         PoseMessage(imu_ns, kImuFrameId, s.T_world_imu));
    }
    const RosbagTopics topics;
    for (int cam = 0; cam < 2; ++cam) {
      const cv::Mat& image = cam == 0 ? frame.left : frame.right;
      sensor_msgs::Image m;
      m.header.stamp = stamp;
      m.header.frame_id = cam == 0 ? kLeftFrameId : kRightFrameId;
      m.height = static_cast<uint32_t>(image.rows);
      m.width = static_cast<uint32_t>(image.cols);
      m.encoding = "mono8";
      m.is_bigendian = 0;
      m.step = static_cast<uint32_t>(image.cols);
      m.data.resize(static_cast<size_t>(image.rows) * image.cols);
      for (int r = 0; r < image.rows; ++r)
        std::copy(image.ptr<uint8_t>(r), image.ptr<uint8_t>(r) + image.cols,
                  m.data.begin() + static_cast<size_t>(r) * image.cols);
      sensor_msgs::CameraInfo info = impl_->info[cam];
      info.header.stamp = stamp;
      impl_->bag.write(cam == 0 ? topics.left : topics.right, stamp, m);
      impl_->bag.write(CameraInfoTopic(cam == 0 ? topics.left : topics.right), stamp, info);
    }
    if (!depth_mm.empty()) {
      sensor_msgs::Image m;
      m.header.stamp = stamp;
      m.header.frame_id = kLeftFrameId;
      m.height = static_cast<uint32_t>(depth_mm.rows);
      m.width = static_cast<uint32_t>(depth_mm.cols);
      m.encoding = "16UC1";
      m.is_bigendian = 0;  // this machine's order (x86, ARM: little-endian)
      m.step = static_cast<uint32_t>(depth_mm.cols * 2);
      m.data.resize(static_cast<size_t>(m.step) * depth_mm.rows);
      for (int r = 0; r < depth_mm.rows; ++r)
        std::memcpy(m.data.data() + static_cast<size_t>(r) * m.step, depth_mm.ptr(r), m.step);
      impl_->bag.write(topics.depth, stamp, m);
    }
    if (frame.has_gt)
      impl_->bag.write(topics.ground_truth, stamp,
                       PoseMessage(stamp_ns, kLeftFrameId, frame.T_world_cam0));
  } catch (const std::exception& e) {
    return Fail(error, impl_->path + ": writing the bag failed: " + e.what());
  }
  return true;
}

bool RosbagWriter::Close(std::string* error) {
  if (!impl_->open) return true;
  impl_->open = false;
  try {
    impl_->bag.close();
  } catch (const std::exception& e) {
    return Fail(error, impl_->path + ": closing the bag failed: " + e.what());
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// Reader

namespace {

// Largest |entry| difference for "this camera_info is already rectified" (R = I, K = P's).
constexpr double kRectifiedTolerance = 1e-12;

struct TopicInfo {
  std::string type;
  size_t messages = 0;
};

std::string TopicList(const std::map<std::string, TopicInfo>& topics) {
  if (topics.empty()) return "the bag has no messages at all";
  std::string s = "topics in the bag:";
  for (const auto& [name, info] : topics)
    s += " " + name + " (" + info.type + ", " + std::to_string(info.messages) + ")";
  return s;
}

// A grey image of a sensor_msgs/Image; false with the problem in *why.
bool ImageToGrey(const sensor_msgs::Image& m, cv::Mat* grey, std::string* why) {
  int channels = 0;
  if (m.encoding == "mono8" || m.encoding == "8UC1")
    channels = 1;
  else if (m.encoding == "rgb8" || m.encoding == "bgr8")
    channels = 3;
  else {
    *why = "encoding '" + m.encoding + "', expected mono8 (or 8UC1, rgb8, bgr8)";
    return false;
  }
  if (m.width == 0 || m.height == 0) {
    *why = "empty image (" + std::to_string(m.width) + "x" + std::to_string(m.height) + ")";
    return false;
  }
  if (m.step < m.width * channels || m.data.size() < static_cast<size_t>(m.step) * m.height) {
    *why = "step " + std::to_string(m.step) + " and " + std::to_string(m.data.size()) +
           " data bytes do not hold " + std::to_string(m.width) + "x" + std::to_string(m.height) +
           " " + m.encoding + " pixels";
    return false;
  }
  const cv::Mat view(static_cast<int>(m.height), static_cast<int>(m.width),
                     channels == 1 ? CV_8UC1 : CV_8UC3, const_cast<uint8_t*>(m.data.data()),
                     m.step);
  if (channels == 1)
    *grey = view.clone();
  else
    cv::cvtColor(view, *grey, m.encoding == "rgb8" ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
  return true;
}

bool IsRectifiedInfo(const sensor_msgs::CameraInfo& c) {
  for (double d : c.D)
    if (std::abs(d) > kRectifiedTolerance) return false;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) {
      if (std::abs(c.R[3 * r + k] - (r == k ? 1.0 : 0.0)) > kRectifiedTolerance) return false;
      if (std::abs(c.K[3 * r + k] - c.P[4 * r + k]) > kRectifiedTolerance) return false;
    }
  return true;
}

}  // namespace

struct RosbagReader::Impl {
  std::string path;
  Options options;
  rosbag::Bag bag;
  std::vector<rosbag::MessageInstance> images[2];    // the paired frames' messages
  std::map<int64_t, rosbag::MessageInstance> depth;  // the depth topic's, by stamp
  std::vector<int64_t> t_ns;                         // the frames' stamps
  size_t unpaired = 0;
  StereoRectification rectification;
  std::vector<int64_t> imu_ns;
  std::vector<sim::ImuSample> imu;
  sim::ImuOptions imu_options;
  std::vector<StampedPose> gt;  // the left (raw) camera in the world
  std::vector<int64_t> gt_ns;   // their stamps
  std::vector<long> gt_index;
  bool has_gt = false;
  std::string left_frame_id;

  std::string Where(const std::string& topic) const { return path + ": topic " + topic + ": "; }
  // Whether `topic` is in the bag (*present); false, naming it, when it holds another type.
  bool CheckTopic(const std::map<std::string, TopicInfo>& topics, const std::string& topic,
                  const std::string& type, bool* present, std::string* error) const {
    const auto it = topics.find(topic);
    *present = it != topics.end();
    if (*present && it->second.type != type)
      return Fail(error, Where(topic) + "type " + it->second.type + ", expected " + type);
    return true;
  }
  bool IndexImages(const std::map<std::string, TopicInfo>& topics, std::string* error);
  bool ReadCalibration(const std::map<std::string, TopicInfo>& topics, std::string* error);
  bool ReadImu(const std::map<std::string, TopicInfo>& topics, std::string* error);
  bool IndexDepth(const std::map<std::string, TopicInfo>& topics, std::string* error);
  bool Depth(size_t index, cv::Mat* depth_m, std::string* error) const;
  bool ReadGroundTruth(const std::map<std::string, TopicInfo>& topics, std::string* error);
  bool Image(int cam, size_t index, cv::Mat* grey, std::string* error) const;
};

RosbagReader::RosbagReader() : impl_(new Impl) {}
RosbagReader::~RosbagReader() = default;

bool RosbagReader::Impl::IndexImages(const std::map<std::string, TopicInfo>& topics,
                                     std::string* error) {
  std::map<int64_t, rosbag::MessageInstance> by_stamp[2];
  for (int cam = 0; cam < 2; ++cam) {
    const std::string& topic = cam == 0 ? options.topics.left : options.topics.right;
    bool present = false;
    if (!CheckTopic(topics, topic, "sensor_msgs/Image", &present, error)) return false;
    if (!present)
      return Fail(error, Where(topic) + "no messages (" + TopicList(topics) +
                             "; choose the image topics with --left / --right)");
    rosbag::View view(bag, rosbag::TopicQuery(topic));
    for (const rosbag::MessageInstance& m : view) {
      const sensor_msgs::Image::ConstPtr image = m.instantiate<sensor_msgs::Image>();
      if (!image) return Fail(error, Where(topic) + "a message is not a sensor_msgs/Image");
      const int64_t stamp = StampNs(image->header.stamp);
      if (by_stamp[cam].count(stamp))
        return Fail(error, Where(topic) + "two images stamped " + std::to_string(stamp) + " ns");
      if (by_stamp[cam].empty()) {  // the first image says what the topic holds
        cv::Mat grey;
        std::string why;
        if (!ImageToGrey(*image, &grey, &why))
          return Fail(error,
                      Where(topic) + "image stamped " + std::to_string(stamp) + " ns: " + why);
        if (cam == 0) left_frame_id = image->header.frame_id;
      }
      by_stamp[cam].emplace(stamp, m);
    }
  }
  for (const auto& [stamp, m] : by_stamp[0]) {
    const auto it = by_stamp[1].find(stamp);
    if (it == by_stamp[1].end()) continue;
    t_ns.push_back(stamp);
    images[0].push_back(m);
    images[1].push_back(it->second);
  }
  unpaired = by_stamp[0].size() + by_stamp[1].size() - 2 * t_ns.size();
  if (t_ns.empty())
    return Fail(error, path + ": no stereo pair: no stamp of " + options.topics.left +
                           " is also on " + options.topics.right);
  return true;
}

bool RosbagReader::Impl::ReadCalibration(const std::map<std::string, TopicInfo>& topics,
                                         std::string* error) {
  if (!options.calib_left.empty() || !options.calib_right.empty()) {
    // EuRoC sensor.yaml files, rectified as `eval --format euroc` does.
    if (options.calib_left.empty() || options.calib_right.empty())
      return Fail(error, "--calib needs two EuRoC sensor.yaml files (cam0, cam1)");
    EurocCameraCalibration cam[2];
    return ReadEurocSensorYaml(options.calib_left, &cam[0], error) &&
           ReadEurocSensorYaml(options.calib_right, &cam[1], error) &&
           ComputeStereoRectification(cam[0], cam[1], options.rectification, &rectification, error);
  }
  sensor_msgs::CameraInfo info[2];
  for (int cam = 0; cam < 2; ++cam) {
    const std::string topic =
        CameraInfoTopic(cam == 0 ? options.topics.left : options.topics.right);
    bool present = false;
    if (!CheckTopic(topics, topic, "sensor_msgs/CameraInfo", &present, error)) return false;
    if (!present)
      return Fail(error, Where(topic) +
                             "no messages: the calibration comes from camera_info or "
                             "from --calib cam0.yaml cam1.yaml (EuRoC sensor.yaml)");
    rosbag::View view(bag, rosbag::TopicQuery(topic));
    const sensor_msgs::CameraInfo::ConstPtr first =
        view.begin()->instantiate<sensor_msgs::CameraInfo>();
    if (!first) return Fail(error, Where(topic) + "a message is not a sensor_msgs/CameraInfo");
    info[cam] = *first;
  }
  const std::string where = Where(CameraInfoTopic(options.topics.left)) + "and " +
                            CameraInfoTopic(options.topics.right) + ": ";
  if (info[0].width != info[1].width || info[0].height != info[1].height)
    return Fail(error, where + "the two cameras have different image sizes");
  for (int k : {0, 1, 2, 5, 6})
    if (info[0].P[k] != info[1].P[k])
      return Fail(error, where + "P differs between the cameras beyond column 4 (P[" +
                             std::to_string(k) + "]): not a rectified stereo pair");
  vo::StereoCamera& c = rectification.camera;
  c.width = static_cast<int>(info[0].width);
  c.height = static_cast<int>(info[0].height);
  c.fx_px = info[0].P[0];
  c.fy_px = info[0].P[5];
  c.cx_px = info[0].P[2];
  c.cy_px = info[0].P[6];
  c.baseline_m = (info[0].P[3] - info[1].P[3]) / c.fx_px;  // as the KITTI reader's calib.txt
  std::string why;
  if (!c.IsValid(&why))
    return Fail(error, where + why + " (baseline = (P_left[3] - P_right[3]) / fx)");
  for (int cam = 0; cam < 2; ++cam)
    if (!IsRectifiedInfo(info[cam]))
      return Fail(error,
                  Where(CameraInfoTopic(cam == 0 ? options.topics.left : options.topics.right)) +
                      "not a rectified pinhole (distortion D not all 0, R not the "
                      "identity or K not P's left 3x3): raw pairs are read with --calib "
                      "cam0.yaml cam1.yaml (EuRoC sensor.yaml), rectified as --format euroc");
  return true;
}

bool RosbagReader::Impl::ReadImu(const std::map<std::string, TopicInfo>& topics,
                                 std::string* error) {
  const std::string& topic = options.topics.imu;
  bool present = false;
  if (!CheckTopic(topics, topic, "sensor_msgs/Imu", &present, error)) return false;
  if (!present) return true;  // no IMU
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  double gyro_var = 0.0, accel_var = 0.0;
  for (const rosbag::MessageInstance& m : view) {
    const sensor_msgs::Imu::ConstPtr s = m.instantiate<sensor_msgs::Imu>();
    if (!s) return Fail(error, Where(topic) + "a message is not a sensor_msgs/Imu");
    const int64_t stamp = StampNs(s->header.stamp);
    if (!imu_ns.empty() && stamp <= imu_ns.back())
      return Fail(error, Where(topic) + "stamp " + std::to_string(stamp) +
                             " ns is not after the previous sample's " +
                             std::to_string(imu_ns.back()) + " ns");
    sim::ImuSample sample;
    sample.time_s = dataset_internal::NsToSeconds(stamp);
    sample.gyro_radps = {s->angular_velocity.x, s->angular_velocity.y, s->angular_velocity.z};
    sample.accel_mps2 = {s->linear_acceleration.x, s->linear_acceleration.y,
                         s->linear_acceleration.z};
    if (!sample.gyro_radps.allFinite() || !sample.accel_mps2.allFinite())
      return Fail(error,
                  Where(topic) + "sample stamped " + std::to_string(stamp) + " ns is not finite");
    if (imu.empty()) {
      gyro_var = s->angular_velocity_covariance[0];
      accel_var = s->linear_acceleration_covariance[0];
    }
    imu_ns.push_back(stamp);
    imu.push_back(sample);
  }
  // The rate from the median interval (to 1 mHz), the densities from the first covariances
  // (sigma^2 = density^2 * rate) where given (> 0); otherwise sim::ImuOptions' defaults.
  if (imu_ns.size() >= 2) {
    std::vector<int64_t> dt;
    for (size_t i = 1; i < imu_ns.size(); ++i) dt.push_back(imu_ns[i] - imu_ns[i - 1]);
    std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
    imu_options.rate_hz = std::round(1e12 / static_cast<double>(dt[dt.size() / 2])) / 1e3;
  }
  if (gyro_var > 0.0) imu_options.gyro_noise_density = std::sqrt(gyro_var / imu_options.rate_hz);
  if (accel_var > 0.0) imu_options.accel_noise_density = std::sqrt(accel_var / imu_options.rate_hz);
  return true;
}

bool RosbagReader::Impl::IndexDepth(const std::map<std::string, TopicInfo>& topics,
                                    std::string* error) {
  const std::string& topic = options.topics.depth;
  bool present = false;
  if (!CheckTopic(topics, topic, "sensor_msgs/Image", &present, error)) return false;
  if (!present) return true;  // no depth
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    const sensor_msgs::Image::ConstPtr image = m.instantiate<sensor_msgs::Image>();
    if (!image) return Fail(error, Where(topic) + "a message is not a sensor_msgs/Image");
    depth.emplace(StampNs(image->header.stamp), m);
  }
  return true;
}

// Depth as the KITTI reader gives it: 16UC1 millimetres * 1e-3 (32FC1 metres as they are),
// CV_32FC1 of the image size; empty when the frame's stamp has no depth message.
bool RosbagReader::Impl::Depth(size_t index, cv::Mat* depth_m, std::string* error) const {
  const auto it = depth.find(t_ns[index]);
  if (it == depth.end()) return true;
  const sensor_msgs::Image::ConstPtr m = it->second.instantiate<sensor_msgs::Image>();
  const std::string at =
      Where(options.topics.depth) + "image stamped " + std::to_string(t_ns[index]) + " ns: ";
  const bool mm = m && m->encoding == "16UC1";
  if (!m || !(mm || m->encoding == "32FC1") || m->is_bigendian)
    return Fail(error, at + "expected a little-endian 16UC1 (mm) or 32FC1 (m) depth image");
  const size_t pixel = mm ? 2 : 4;
  if (static_cast<int>(m->width) != rectification.camera.width ||
      static_cast<int>(m->height) != rectification.camera.height || m->step < m->width * pixel ||
      m->data.size() < static_cast<size_t>(m->step) * m->height)
    return Fail(error, at + "size or step does not match the camera's images");
  const cv::Mat view(static_cast<int>(m->height), static_cast<int>(m->width),
                     mm ? CV_16UC1 : CV_32FC1, const_cast<uint8_t*>(m->data.data()), m->step);
  if (mm)
    view.convertTo(*depth_m, CV_32FC1, 1e-3);
  else
    *depth_m = view.clone();
  return true;
}

bool RosbagReader::Impl::ReadGroundTruth(const std::map<std::string, TopicInfo>& topics,
                                         std::string* error) {
  const std::string& topic = options.topics.ground_truth;
  bool present = false;
  if (!CheckTopic(topics, topic, "geometry_msgs/TransformStamped", &present, error)) return false;
  if (!present) return true;  // no ground truth
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    const geometry_msgs::TransformStamped::ConstPtr g =
        m.instantiate<geometry_msgs::TransformStamped>();
    if (!g) return Fail(error, Where(topic) + "a message is not a geometry_msgs/TransformStamped");
    const int64_t stamp = StampNs(g->header.stamp);
    const std::string at = Where(topic) + "pose stamped " + std::to_string(stamp) + " ns: ";
    if (g->child_frame_id != left_frame_id)
      return Fail(error, at + "child_frame_id '" + g->child_frame_id +
                             "', expected the left images' frame_id '" + left_frame_id +
                             "' (the ground truth is the left camera's pose)");
    if (!gt_ns.empty() && stamp <= gt_ns.back())
      return Fail(error, at + "not after the previous pose's stamp");
    // As ReadTum (trajectory_io.h): a unit quaternion (w, x, y, z), normalised.
    Eigen::Quaterniond q(g->transform.rotation.w, g->transform.rotation.x, g->transform.rotation.y,
                         g->transform.rotation.z);
    const Eigen::Vector3d p(g->transform.translation.x, g->transform.translation.y,
                            g->transform.translation.z);
    if (!p.allFinite() || !std::isfinite(q.norm()) ||
        std::abs(q.norm() - 1.0) > kTumQuaternionNormTolerance)
      return Fail(error, at + "expected a finite position and a unit quaternion, norm " +
                             FormatDouble(q.norm()));
    q.normalize();
    StampedPose pose;
    pose.time_s = dataset_internal::NsToSeconds(stamp);
    pose.T_world_cam.setIdentity();
    pose.T_world_cam.linear() = q.toRotationMatrix();
    pose.T_world_cam.translation() = p;
    gt.push_back(pose);
    gt_ns.push_back(stamp);
  }
  std::vector<double> frame_s;
  for (int64_t t : t_ns) frame_s.push_back(dataset_internal::NsToSeconds(t));
  gt_index = AssociateGroundTruth(frame_s, gt, options.gt_max_difference_s);
  if (dataset_internal::CountAssociated(gt_index) == 0)
    return Fail(error, Where(topic) + "no pose within " +
                           FormatDouble(options.gt_max_difference_s) + " s of any of the " +
                           std::to_string(t_ns.size()) + " frames: a different clock?");
  has_gt = true;
  return true;
}

bool RosbagReader::Open(const std::string& path, const Options& options, std::string* error) {
  impl_.reset(new Impl);
  Impl& d = *impl_;
  d.path = path;
  d.options = options;
  if (!(options.gt_max_difference_s > 0.0))
    return Fail(error, "RosbagReader: gt_max_difference_s must be > 0");
  try {
    d.bag.open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    return Fail(error, path + ": not a readable ROS bag (" + e.what() + ")");
  }
  try {
    std::map<std::string, TopicInfo> topics;
    rosbag::View all(d.bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      TopicInfo& t = topics[c->topic];
      t.type = c->datatype;
    }
    for (auto& [name, info] : topics) {
      rosbag::View view(d.bag, rosbag::TopicQuery(name));
      info.messages = view.size();
    }
    return d.IndexImages(topics, error) && d.ReadCalibration(topics, error) &&
           d.ReadImu(topics, error) && d.IndexDepth(topics, error) &&
           d.ReadGroundTruth(topics, error);
  } catch (const std::exception& e) {
    return Fail(error, path + ": reading the bag failed (" + e.what() + ")");
  }
}

size_t RosbagReader::size() const { return impl_->t_ns.size(); }
size_t RosbagReader::unpaired_frames() const { return impl_->unpaired; }
const StereoRectification& RosbagReader::rectification() const { return impl_->rectification; }
bool RosbagReader::has_imu() const { return !impl_->imu.empty(); }
const sim::ImuOptions& RosbagReader::imu() const { return impl_->imu_options; }
std::string RosbagReader::ground_truth_topic() const {
  return impl_->has_gt ? impl_->options.topics.ground_truth : std::string();
}
size_t RosbagReader::ground_truth_frames() const {
  return dataset_internal::CountAssociated(impl_->gt_index);
}

bool RosbagReader::Impl::Image(int cam, size_t index, cv::Mat* grey, std::string* error) const {
  const std::string& topic = cam == 0 ? options.topics.left : options.topics.right;
  const sensor_msgs::Image::ConstPtr m = images[cam][index].instantiate<sensor_msgs::Image>();
  if (!m) return Fail(error, Where(topic) + "a message is not a sensor_msgs/Image");
  std::string why;
  if (!ImageToGrey(*m, grey, &why))
    return Fail(error,
                Where(topic) + "image stamped " + std::to_string(t_ns[index]) + " ns: " + why);
  const int width =
      rectification.map0_x.empty() ? rectification.camera.width : rectification.map0_x.cols;
  const int height =
      rectification.map0_x.empty() ? rectification.camera.height : rectification.map0_x.rows;
  if (grey->cols != width || grey->rows != height)
    return Fail(error, Where(topic) + "image stamped " + std::to_string(t_ns[index]) + " ns is " +
                           std::to_string(grey->cols) + "x" + std::to_string(grey->rows) +
                           ", the calibration says " + std::to_string(width) + "x" +
                           std::to_string(height));
  return true;
}

bool RosbagReader::ReadFrame(size_t index, DatasetFrame* frame, std::string* error) const {
  const Impl& d = *impl_;
  if (!dataset_internal::CheckFrameIndex(d.path, index, d.t_ns.size(), error)) return false;
  *frame = DatasetFrame();
  try {
    if (!d.Image(0, index, &frame->left, error) || !d.Image(1, index, &frame->right, error) ||
        !d.Depth(index, &frame->depth_m, error))
      return false;
  } catch (const std::exception& e) {
    return Fail(error,
                d.path + ": reading frame " + std::to_string(index) + " failed (" + e.what() + ")");
  }
  frame->time_s = dataset_internal::NsToSeconds(d.t_ns[index]);
  if (d.has_gt && d.gt_index[index] >= 0) {
    frame->has_gt = true;
    frame->T_world_cam0 = d.gt[d.gt_index[index]].T_world_cam;
  }
  ImuSamplesBetween(d.imu_ns, d.imu, index == 0 ? INT64_MIN : d.t_ns[index - 1], d.t_ns[index],
                    &frame->imu);
  RectifyFrame(d.rectification, frame);
  return true;
}

#else  // without VOBENCH_ROSBAG: every entry refuses

struct RosbagWriter::Impl {};
RosbagWriter::RosbagWriter() = default;
RosbagWriter::~RosbagWriter() = default;
bool RosbagWriter::Open(const std::string&, const vo::StereoCamera&, const sim::ImuOptions&,
                        std::string* error) {
  return Fail(error, RosbagUnavailable());
}
bool RosbagWriter::Add(const DatasetFrame&, const cv::Mat&, int64_t, int64_t, std::string* error) {
  return Fail(error, RosbagUnavailable());
}
bool RosbagWriter::Close(std::string*) { return true; }

struct RosbagReader::Impl {
  StereoRectification rectification;
  sim::ImuOptions imu;
};
RosbagReader::RosbagReader() : impl_(new Impl) {}
RosbagReader::~RosbagReader() = default;
bool RosbagReader::Open(const std::string&, const Options&, std::string* error) {
  return Fail(error, RosbagUnavailable());
}
size_t RosbagReader::size() const { return 0; }
size_t RosbagReader::unpaired_frames() const { return 0; }
const StereoRectification& RosbagReader::rectification() const { return impl_->rectification; }
bool RosbagReader::has_imu() const { return false; }
const sim::ImuOptions& RosbagReader::imu() const { return impl_->imu; }
std::string RosbagReader::ground_truth_topic() const { return ""; }
size_t RosbagReader::ground_truth_frames() const { return 0; }
bool RosbagReader::ReadFrame(size_t, DatasetFrame*, std::string* error) const {
  return Fail(error, RosbagUnavailable());
}

#endif  // VOBENCH_ROSBAG

}  // namespace harness
