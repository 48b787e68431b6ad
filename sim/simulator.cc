#include "sim/simulator.h"

#include <mujoco/mujoco.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstring>
#include <mutex>
#include <opencv2/imgproc.hpp>

#include "sim/floor_plan.h"
#include "sim/lighting.h"
#include "sim/noise.h"
#include "sim/path_follower.h"
#include "sim/people.h"
#include "sim/random.h"
#include "sim/renderer.h"
#include "sim/scene_walls.h"
#include "sim/textures.h"

namespace sim {
namespace {

// Names the scene must define (see scenes/robot_p2dx.xml).
constexpr const char* kRobotBody = "robot";
constexpr const char* kRobotJoint = "robot_root";
constexpr const char* kLeftActuator = "drive_left";
constexpr const char* kRightActuator = "drive_right";
constexpr const char* kCam0 = "cam0";
constexpr const char* kCam1 = "cam1";
constexpr const char* kImuSite = "imu";
constexpr const char* kImuGyro = "imu_gyro";
constexpr const char* kImuAccel = "imu_accel";
constexpr double kStoppedSpeedMps = 0.005;  // the robot counts as standing still below this

// MuJoCo reports warnings through a global hook: log them and count them so that the
// simulator (and its tests) can fail on any.
int g_warning_count = 0;
std::mutex g_warning_mutex;
void WarningHook(const char* msg) {
  std::lock_guard<std::mutex> lock(g_warning_mutex);
  ++g_warning_count;
  spdlog::warn("MuJoCo: {}", msg);
}

uint64_t HashName(const std::string& s) {  // FNV-1a
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

double YawOf(const mjtNum* quat) {  // MuJoCo quaternion (w, x, y, z)
  const double w = quat[0], x = quat[1], y = quat[2], z = quat[3];
  return std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
}

// Camera pose in the world with computer-vision axes (x right, y down, z forward) from
// MuJoCo's camera frame (x right, y up, looking along -z).
Eigen::Isometry3d CameraPoseCv(const mjData* d, int cam_id) {
  Eigen::Matrix3d R_world_mjcam;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R_world_mjcam(r, c) = d->cam_xmat[9 * cam_id + 3 * r + c];
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_world_mjcam * Eigen::Vector3d(1, -1, -1).asDiagonal();
  T.translation() = Eigen::Vector3d(d->cam_xpos[3 * cam_id], d->cam_xpos[3 * cam_id + 1],
                                    d->cam_xpos[3 * cam_id + 2]);
  return T;
}

Eigen::Isometry3d BodyPose(const mjData* d, int body_id) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const mjtNum* q = d->xquat + 4 * body_id;
  T.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  T.translation() =
      Eigen::Vector3d(d->xpos[3 * body_id], d->xpos[3 * body_id + 1], d->xpos[3 * body_id + 2]);
  return T;
}

// Fills every texture whose name starts with a known kind ("wall_", "floor_", ...), styles
// included ("wall-busy_", textures.h: ParseTextureName), with the procedural generator, sized
// from the plane geom that uses it.
bool FillTextures(mjModel* m, uint64_t seed, const std::string& scene, std::string* error) {
  for (int t = 0; t < m->ntex; ++t) {
    const std::string name = mj_id2name(m, mjOBJ_TEXTURE, t) ? mj_id2name(m, mjOBJ_TEXTURE, t) : "";
    TextureKind kind;
    TextureOptions options;  // the name's styles (a floor plan's surfaces) over the defaults
    if (!ParseTextureName(name, &kind, &options)) continue;
    if (m->tex_type[t] != mjTEXTURE_2D) {
      *error = scene + ": texture '" + name + "' must be type=\"2d\" to be generated";
      return false;
    }
    // The plane geom whose material carries this texture gives the surface size.
    int geom = -1;
    for (int g = 0; g < m->ngeom && geom < 0; ++g) {
      const int mat = m->geom_matid[g];
      if (mat >= 0 && m->mat_texid[mat] == t && m->geom_type[g] == mjGEOM_PLANE) geom = g;
    }
    if (geom < 0) {
      *error = scene + ": texture '" + name +
               "' is not used by any plane geom (generated textures are sized from their plane)";
      return false;
    }
    const double width_m = 2.0 * m->geom_size[3 * geom];
    const double height_m = 2.0 * m->geom_size[3 * geom + 1];
    const int w = m->tex_width[t], h = m->tex_height[t];
    options.px_per_m = w / width_m;
    cv::Mat img =
        GenerateTexture(kind, width_m, height_m, DeriveSeed(seed, HashName(name)), options);
    if (img.empty() || img.type() != CV_8UC3) {
      *error = scene + ": texture generator failed for '" + name + "'";
      return false;
    }
    if (img.cols != w || img.rows != h) cv::resize(img, img, cv::Size(w, h), 0, 0, cv::INTER_AREA);
    cv::cvtColor(img, img, cv::COLOR_BGR2RGB);
    unsigned char* dst = m->tex_rgb + m->tex_adr[t];
    for (int r = 0; r < h; ++r)
      std::memcpy(dst + static_cast<size_t>(r) * w * 3, img.ptr(r), static_cast<size_t>(w) * 3);
  }
  return true;
}

}  // namespace

void IntrinsicsFromFovy(double fovy_deg, int width, int height, double* fx_px, double* fy_px,
                        double* cx_px, double* cy_px) {
  // MuJoCo's frustum spans the viewport's edges: half height = tan(fovy/2) at unit depth.
  *fy_px = 0.5 * height / std::tan(0.5 * fovy_deg * M_PI / 180.0);
  *fx_px = *fy_px;
  // The optical axis passes through the viewport centre, an integer-pixel coordinate of
  // (W-1)/2 when pixel centres sit at integers.
  *cx_px = 0.5 * (width - 1);
  *cy_px = 0.5 * (height - 1);
}

struct Simulator::Impl {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  std::unique_ptr<OffscreenRenderer> renderer;
  DistortedView lens;  // with camera.distortion: the wide render and its maps to the lens
  std::unique_ptr<PathFollower> follower;
  int body = -1, root_joint = -1, act_left = -1, act_right = -1, cam0 = -1, cam1 = -1;
  long start_step = 0;    // physics step of frame time 0 (after settling)
  int next_frame = 0;     // index of the frame being assembled
  bool finished = false;  // path done and robot at rest: no further frames start
  int warnings_at_start = 0;
  // IMU: site, sensordata addresses, physics steps per sample, noise, samples not yet handed out.
  int imu_site = -1, gyro_adr = -1, accel_adr = -1;
  long imu_every = 1;
  long imu_pre_roll_steps = 0;  // IMU samples start this many steps before start_step
  std::unique_ptr<ImuNoiseModel> imu_noise;
  std::vector<ImuSample> imu_pending;
  // Navigation (sim/navigation.h): the belief the follower steers on in the closed loop, the
  // commands issued since the last frame's time (replayed on its fix), what the robot did.
  bool closed_loop = false;
  PlanarPose belief;
  PlanarPose belief_at_frame;
  std::vector<DriveCommand> commands_since_frame;
  StepEstimator step_estimator;
  NavigationReport nav;
  std::vector<char> robot_geom, building_geom;  // per geom: on the robot; the building to touch
  bool touching = false;                        // in contact with the building at the last step
  // People, lights and auto-exposure (issue #34; sim/people.h, sim/lighting.h).
  People people;
  std::vector<int> person_body;  // body id of each person
  std::unique_ptr<SceneLighting> lighting;
  std::unique_ptr<AutoExposure> auto_exposure;

  ~Impl() {
    renderer.reset();
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
};

Simulator::Simulator(const Scenario& scenario) : scenario_(scenario), impl_(new Impl) {}
Simulator::~Simulator() = default;

const std::string& Simulator::gl_renderer() const { return impl_->renderer->gl_renderer(); }

std::unique_ptr<Simulator> Simulator::Create(const Scenario& scenario, std::string* error) {
  std::string why;
  if (!scenario.IsValid(&why)) {
    *error = (scenario.source_path.empty() ? "scenario" : scenario.source_path) + ": " + why;
    return nullptr;
  }
  mju_user_warning = WarningHook;
  std::unique_ptr<Simulator> sim(new Simulator(scenario));
  Impl& im = *sim->impl_;
  const std::string& scene = scenario.scene_path;

  // An MJCF file or a floor plan (sim/floor_plan.h), with the people's bodies (sim/people.h).
  im.m = LoadSceneModel(scene, error,
                        scenario.people.count > 0 ? PeopleMjcf(scenario.people) : std::string());
  if (!im.m) return nullptr;
  mjModel* m = im.m;
  im.body = mj_name2id(m, mjOBJ_BODY, kRobotBody);
  im.root_joint = mj_name2id(m, mjOBJ_JOINT, kRobotJoint);
  im.act_left = mj_name2id(m, mjOBJ_ACTUATOR, kLeftActuator);
  im.act_right = mj_name2id(m, mjOBJ_ACTUATOR, kRightActuator);
  im.cam0 = mj_name2id(m, mjOBJ_CAMERA, kCam0);
  im.cam1 = mj_name2id(m, mjOBJ_CAMERA, kCam1);
  if (im.body < 0 || im.root_joint < 0 || im.act_left < 0 || im.act_right < 0 || im.cam0 < 0 ||
      im.cam1 < 0) {
    *error = scene +
             ": the scene must contain the robot (body 'robot' with free joint 'robot_root', "
             "actuators 'drive_left'/'drive_right', cameras 'cam0'/'cam1'); include robot_p2dx.xml";
    return nullptr;
  }
  if (m->jnt_type[im.root_joint] != mjJNT_FREE || m->cam_bodyid[im.cam0] != im.body ||
      m->cam_bodyid[im.cam1] != im.body) {
    *error = scene +
             ": joint 'robot_root' must be a free joint and cameras 'cam0'/'cam1' must sit on body "
             "'robot'";
    return nullptr;
  }
  // The IMU: a gyro and an accelerometer on site 'imu' of the robot.
  im.imu_site = mj_name2id(m, mjOBJ_SITE, kImuSite);
  const int gyro = mj_name2id(m, mjOBJ_SENSOR, kImuGyro);
  const int accel = mj_name2id(m, mjOBJ_SENSOR, kImuAccel);
  if (im.imu_site < 0 || m->site_bodyid[im.imu_site] != im.body || gyro < 0 || accel < 0 ||
      m->sensor_type[gyro] != mjSENS_GYRO || m->sensor_type[accel] != mjSENS_ACCELEROMETER ||
      m->sensor_objid[gyro] != im.imu_site || m->sensor_objid[accel] != im.imu_site) {
    *error = scene +
             ": the robot must carry the IMU: site 'imu' on body 'robot' with sensors gyro "
             "'imu_gyro' and accelerometer 'imu_accel' on it; include robot_p2dx.xml";
    return nullptr;
  }
  im.gyro_adr = m->sensor_adr[gyro];
  im.accel_adr = m->sensor_adr[accel];
  im.imu_every = std::lround(1.0 / (scenario.imu.rate_hz * scenario.physics_dt_s));
  const Eigen::Isometry3d T_body_imu = ImuPoseOnBody(scenario.imu);
  const Eigen::Quaterniond q_body_imu(T_body_imu.linear());
  for (int i = 0; i < 3; ++i) m->site_pos[3 * im.imu_site + i] = T_body_imu.translation()[i];
  m->site_quat[4 * im.imu_site + 0] = q_body_imu.w();
  m->site_quat[4 * im.imu_site + 1] = q_body_imu.x();
  m->site_quat[4 * im.imu_site + 2] = q_body_imu.y();
  m->site_quat[4 * im.imu_site + 3] = q_body_imu.z();
  sim->calibration_.T_body_imu = T_body_imu;
  im.imu_noise = std::make_unique<ImuNoiseModel>(scenario.imu, ImuNoiseSeed(scenario.seed));

  m->opt.timestep = scenario.physics_dt_s;
  // A path through a wall (scenarios built in code; files are checked when read).
  int waypoint = -1;
  std::vector<SceneWall> walls;
  std::vector<SceneFloor> floors;
  WallsOfModel(m, &walls, &floors);  // from the model just loaded: no second load of the scene
  if (const std::string through = PathProblem(scenario, walls, floors, &waypoint);
      !through.empty()) {
    *error = (scenario.source_path.empty() ? "scenario" : scenario.source_path) + ": key 'path[" +
             std::to_string(waypoint) + "]': " + through;
    return nullptr;
  }
  if (scenario.people.count > 0) {  // their paths (sim/people.h), then their bodies' textures
    std::vector<PersonPath> paths;
    if (!PlanPeople(scenario, walls, floors, &paths, error) ||
        !im.people.Init(m, scenario.people, std::move(paths), error)) {
      *error = (scenario.source_path.empty() ? "scenario" : scenario.source_path) +
               ": key 'people.count': " + *error;
      return nullptr;
    }
    for (int i = 0; i < scenario.people.count; ++i)
      im.person_body.push_back(mj_name2id(m, mjOBJ_BODY, ("person" + std::to_string(i)).c_str()));
  }
  for (const LightSwitch& sw : scenario.lights.switches)
    if (sw.light < 0 || sw.light >= m->nlight) {
      *error = (scenario.source_path.empty() ? "scenario" : scenario.source_path) +
               ": key 'lights.switch': light " + std::to_string(sw.light) + " of " + scene +
               ", which has " + std::to_string(m->nlight) + " lights";
      return nullptr;
    }
  im.lighting = std::make_unique<SceneLighting>(m, scenario.lights);
  if (scenario.camera.auto_exposure.enabled)
    im.auto_exposure =
        std::make_unique<AutoExposure>(scenario.camera.auto_exposure, 1.0 / scenario.rate_hz);

  // Stereo rig: place both cameras from the scenario (body frame: x forward, y left, z up,
  // origin at the wheel axle, which rests at wheel-radius height).
  const CameraOptions& co = scenario.camera;
  const double pitch = co.pitch_deg * M_PI / 180.0;
  Eigen::Matrix3d R_body_mjcam0;  // camera looks along +x_body, image up = +z_body
  R_body_mjcam0.col(0) = Eigen::Vector3d(0, -1, 0);
  R_body_mjcam0.col(1) = Eigen::Vector3d(0, 0, 1);
  R_body_mjcam0.col(2) = Eigen::Vector3d(-1, 0, 0);
  const Eigen::Matrix3d R_body_mjcam =
      R_body_mjcam0 * Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Quaterniond q_body_mjcam(R_body_mjcam);
  const double z_cam = co.height_m - scenario.robot.wheel_radius_m;
  const Eigen::Vector3d right_dir = R_body_mjcam.col(0);  // camera x (right) in the body frame
  const Eigen::Vector3d centre(co.forward_m, 0.0, z_cam);
  const Eigen::Vector3d p_cam0 = centre - 0.5 * co.baseline_m * right_dir;
  const Eigen::Vector3d p_cam1 = centre + 0.5 * co.baseline_m * right_dir;
  StereoCalibration& cal = sim->calibration_;
  cal.width = co.width;
  cal.height = co.height;
  IntrinsicsFromFovy(co.fovy_deg, co.width, co.height, &cal.fx_px, &cal.fy_px, &cal.cx_px,
                     &cal.cy_px);
  cal.lens = co.distortion;
  int render_width = co.width, render_height = co.height;
  if (co.distortion.any()) {  // render wider, remap to the lens (sim/lens.h)
    if (!MakeDistortedView(co.distortion, cal.fx_px, cal.fy_px, cal.cx_px, cal.cy_px, co.width,
                           co.height, &im.lens, error)) {
      *error = scenario.source_path + ": camera." + *error;
      return nullptr;
    }
    render_width = im.lens.wide_width;
    render_height = im.lens.wide_height;
  }
  for (int k = 0; k < 2; ++k) {
    const int id = k == 0 ? im.cam0 : im.cam1;
    const Eigen::Vector3d& p = k == 0 ? p_cam0 : p_cam1;
    for (int i = 0; i < 3; ++i) m->cam_pos[3 * id + i] = p[i];
    m->cam_quat[4 * id + 0] = q_body_mjcam.w();
    m->cam_quat[4 * id + 1] = q_body_mjcam.x();
    m->cam_quat[4 * id + 2] = q_body_mjcam.y();
    m->cam_quat[4 * id + 3] = q_body_mjcam.z();
    m->cam_fovy[id] = co.distortion.any() ? im.lens.wide_fovy_deg : co.fovy_deg;
    m->cam_mode[id] = mjCAMLIGHT_FIXED;
  }
  cal.baseline_m = co.baseline_m;
  cal.T_body_cam0.linear() = R_body_mjcam * Eigen::Vector3d(1, -1, -1).asDiagonal();
  cal.T_body_cam0.translation() = p_cam0;

  m->vis.global.offwidth = std::max(m->vis.global.offwidth, render_width);
  m->vis.global.offheight = std::max(m->vis.global.offheight, render_height);
  if (m->ntex > kMaxPlanTextures) {  // mjrContext holds 100: the rest would be drawn untextured
    *error = scene + ": " + std::to_string(m->ntex) +
             " textures; MuJoCo's renderer holds at most " + std::to_string(kMaxPlanTextures);
    return nullptr;
  }
  if (!FillTextures(m, scenario.textures.seed, scene, error)) return nullptr;

  im.renderer = OffscreenRenderer::Create(m, render_width, render_height, error);
  if (!im.renderer) {
    *error = "cannot render offscreen: " + *error;
    return nullptr;
  }

  // Robot at the first waypoint, facing the second.
  im.d = mj_makeData(m);
  const int qadr = m->jnt_qposadr[im.root_joint];
  const Eigen::Vector2d dir = scenario.path[1] - scenario.path[0];
  const double yaw = std::atan2(dir.y(), dir.x());
  im.d->qpos[qadr + 0] = scenario.path[0].x();
  im.d->qpos[qadr + 1] = scenario.path[0].y();
  im.d->qpos[qadr + 2] = scenario.robot.wheel_radius_m;
  im.d->qpos[qadr + 3] = std::cos(yaw / 2);
  im.d->qpos[qadr + 4] = 0;
  im.d->qpos[qadr + 5] = 0;
  im.d->qpos[qadr + 6] = std::sin(yaw / 2);
  if (scenario.people.count > 0) im.people.Apply(m, im.d, -scenario.settle_s);
  mj_forward(m, im.d);
  im.follower = std::make_unique<PathFollower>(scenario.path, scenario.robot, scenario.waypoints);
  // Navigation: the belief starts at the known start pose. The building's geoms to touch: those
  // welded to the world that collide, except planes facing up (the floor).
  im.closed_loop = scenario.navigation == "vo";
  im.belief.position = scenario.path[0];
  im.belief.yaw_rad = yaw;
  im.belief_at_frame = im.belief;
  im.nav.mode = scenario.navigation;
  im.robot_geom.assign(m->ngeom, 0);
  im.building_geom.assign(m->ngeom, 0);
  for (int g = 0; g < m->ngeom; ++g) {
    const int b = m->geom_bodyid[g];
    im.robot_geom[g] = m->body_rootid[b] == im.body;
    const bool floor = m->geom_type[g] == mjGEOM_PLANE && im.d->geom_xmat[9 * g + 8] > 0.5;
    im.building_geom[g] = m->body_weldid[b] == 0 && !floor &&
                          (m->geom_contype[g] != 0 || m->geom_conaffinity[g] != 0);
    if (im.building_geom[g]) im.nav.wall_contacts = 0;
  }
  im.start_step = std::lround(scenario.settle_s / scenario.physics_dt_s);
  // The IMU's pre-roll: samples on the last settling steps, a whole number of sample periods.
  im.imu_pre_roll_steps = std::min(
      im.start_step, std::lround(scenario.imu.pre_roll_s * scenario.imu.rate_hz) * im.imu_every);
  im.warnings_at_start = g_warning_count;
  return sim;
}

int Simulator::EstimatedFrames() const {
  double t = 0.0;
  const auto& p = scenario_.path;
  for (size_t i = 1; i < p.size(); ++i) {
    t += (p[i] - p[i - 1]).norm() / scenario_.robot.speed_mps +
         scenario_.robot.speed_mps / scenario_.robot.max_accel_mps2;
    if (i + 1 < p.size() && scenario_.robot.corner_mode == "in_place") {
      const Eigen::Vector2d a = p[i] - p[i - 1], b = p[i + 1] - p[i];
      const double turn = std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)));
      t += turn / (scenario_.robot.turn_rate_dps * M_PI / 180.0) + 1.0;
    }
  }
  return static_cast<int>(t * scenario_.rate_hz) + 1;
}

FrameFate FrameFateOf(const FrameOptions& options, uint64_t seed, int index) {
  FrameFate fate;
  if (!options.any()) return fate;
  SplitMix64 rng(DeriveSeed(seed, static_cast<uint64_t>(index), 3));
  fate.dropped = rng.Uniform() < options.drop_rate;
  const double u = rng.Uniform();
  // Frame 0 is the clock's origin: its stamp stays 0 (no stamp before the sequence starts).
  fate.jitter_s = index == 0 ? 0.0 : options.time_jitter_s * (2.0 * u - 1.0);
  return fate;
}

bool Simulator::Next(StereoFrame* frame, std::string* error) {
  const FrameOptions& options = scenario_.frames;
  if (!options.any()) return Capture(frame, error);
  std::vector<ImuSample> imu;  // the samples of dropped frames, for the next frame kept
  while (Capture(frame, error)) {
    imu.insert(imu.end(), frame->imu.begin(), frame->imu.end());
    const FrameFate fate = FrameFateOf(options, scenario_.seed, frame->index);
    if (fate.dropped) continue;
    frame->time_s += fate.jitter_s;
    frame->imu = std::move(imu);
    return true;
  }
  return false;
}

bool Simulator::Capture(StereoFrame* frame, std::string* error) {
  error->clear();
  Impl& im = *impl_;
  if (im.finished) return false;
  mjModel* m = im.m;
  mjData* d = im.d;
  const Scenario& sc = scenario_;
  const double dt = sc.physics_dt_s;
  const int k = im.next_frame;
  const double t_frame = k / sc.rate_hz;

  // Steps at which this frame is rendered: one, or `motion_blur_samples` spread over the
  // exposure centred on the frame time; ground truth at the frame time itself.
  const bool blur = sc.noise.motion_blur_exposure_s > 0.0;
  const int samples = blur ? sc.noise.motion_blur_samples : 1;
  std::vector<long> sample_steps(samples);
  for (int i = 0; i < samples; ++i) {
    const double off =
        blur ? sc.noise.motion_blur_exposure_s * (static_cast<double>(i) / (samples - 1) - 0.5)
             : 0.0;
    sample_steps[i] = std::max(0l, im.start_step + std::lround((t_frame + off) / dt));
  }
  const long gt_step = im.start_step + std::lround(t_frame / dt);
  const long last_step = std::max(sample_steps.back(), gt_step);

  // Fresh buffers: callers may keep the previous frame's images (cv::Mat shares data).
  frame->left = cv::Mat();
  frame->right = cv::Mat();
  frame->depth_m = cv::Mat();
  cv::Mat acc[2];
  int rendered = 0;
  bool have_gt = false;
  const int qadr = m->jnt_qposadr[im.root_joint];
  const int vadr = m->jnt_dofadr[im.root_joint];
  while (true) {
    // The people where they are at this step, then the kinematics of the current state,
    // consistent with d->time.
    const long step = std::lround(d->time / dt);
    const double t_step = (step - im.start_step) * dt;  // from frame 0
    if (sc.people.count > 0) im.people.Apply(m, d, t_step);
    mj_step1(m, d);
    const PlanarPose truth{Eigen::Vector2d(d->qpos[qadr], d->qpos[qadr + 1]),
                           YawOf(d->qpos + qadr + 3)};
    if (im.closed_loop && im.step_estimator && step >= im.start_step)
      im.belief = im.step_estimator(truth);
    if (step > im.start_step + std::lround(sc.max_duration_s / dt) && im.closed_loop) {
      // A robot steering on its estimate may never get there (stuck on a wall, lost): the run
      // ends at the time limit, the goal not reached.
      im.nav.reached_goal = false;
      im.nav.end_error_m = (truth.position - sc.path.back()).norm();
      im.finished = true;
      return false;
    }
    if (step > im.start_step + std::lround(sc.max_duration_s / dt)) {
      *error = sc.source_path + ": the robot did not finish its path within max_duration_s = " +
               std::to_string(sc.max_duration_s) +
               " s (stuck against a wall, or the path leaves the scene?)";
      return false;
    }
    if (g_warning_count > im.warnings_at_start) {
      *error = sc.scene_path +
               ": MuJoCo warning during simulation (see log); the physics are not trustworthy";
      return false;
    }
    if (step >= im.start_step)
      body_track_.emplace_back(d->xpos[3 * im.body], d->xpos[3 * im.body + 1],
                               d->xpos[3 * im.body + 2]);
    if (step >= im.start_step && im.nav.wall_contacts >= 0) {  // contacts of mj_step1
      bool touching = false;
      for (int i = 0; i < d->ncon && !touching; ++i) {
        const int g1 = d->contact[i].geom1, g2 = d->contact[i].geom2;
        touching = (im.robot_geom[g1] && im.building_geom[g2]) ||
                   (im.robot_geom[g2] && im.building_geom[g1]);
      }
      if (touching && !im.touching) ++im.nav.wall_contacts;
      if (touching) im.nav.wall_contact_s += dt;
      im.touching = touching;
    }

    // Render the samples that fall on this step.
    for (int i = 0; i < samples; ++i) {
      if (sample_steps[i] != step) continue;
      for (int c = 0; c < 2; ++c) {
        cv::Mat rgb, grey;
        cv::Mat* depth = (c == 0 && !blur) ? &frame->depth_m : nullptr;
        im.lighting->Apply(m, t_step);  // lights.* at this render's time (none: no change)
        im.renderer->Render(m, d, c == 0 ? im.cam0 : im.cam1, &rgb, depth);
        cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
        if (acc[c].empty()) acc[c] = cv::Mat::zeros(grey.size(), CV_32FC1);
        cv::accumulate(grey, acc[c]);
      }
      ++rendered;
    }
    if (step == gt_step) {
      frame->T_world_cam0 = CameraPoseCv(d, im.cam0);
      frame->T_world_body = BodyPose(d, im.body);
      people_at_frame_.clear();
      for (int b : im.person_body)
        people_at_frame_.emplace_back(d->xpos[3 * b], d->xpos[3 * b + 1], d->xpos[3 * b + 2]);
      if (blur) im.renderer->Render(m, d, im.cam0, nullptr, &frame->depth_m);
      have_gt = true;
      NavigationFrame nf;
      nf.time_s = t_frame;
      nf.truth = truth;
      nf.believed = im.closed_loop ? im.belief : truth;
      im.nav.frames.push_back(nf);
      im.belief_at_frame = im.belief;
      im.commands_since_frame.clear();
    }
    // End of the path: once the controller is done and the robot stands still, no new frame
    // starts (a frame already under way is completed above).
    const double speed =
        Eigen::Vector3d(d->qvel[vadr], d->qvel[vadr + 1], d->qvel[vadr + 2]).norm();
    if (step >= im.start_step && im.follower->done() && speed < kStoppedSpeedMps && rendered == 0) {
      im.nav.reached_goal = true;
      im.nav.end_error_m = (truth.position - sc.path.back()).norm();
      im.finished = true;
      return false;
    }

    // Control: stand still while settling, then follow the path on the true pose, or on the
    // belief (closed loop: an estimator's, dead-reckoned with the commands between its fixes).
    DriveCommand cmd;
    if (step >= im.start_step) {
      PlanarPose steer = truth;
      if (im.closed_loop) steer = im.belief;
      const size_t target = im.follower->target_index();
      const bool was_done = im.follower->done();
      cmd = im.follower->Update(steer.position, steer.yaw_rad, dt);
      // A waypoint the follower believes reached: where the robot really is.
      const bool reached = im.follower->done() ||
                           (im.follower->target_index() != target && im.follower->stops_at(target));
      if (!was_done && reached) {
        const double err = (truth.position - sc.path[target]).norm();
        if (!(err <= im.nav.max_waypoint_error_m)) im.nav.max_waypoint_error_m = err;
      }
      if (im.closed_loop) {
        im.belief = DeadReckon(im.belief, cmd, dt);
        im.commands_since_frame.push_back(cmd);
      }
    }
    double wl, wr;
    WheelSpeeds(cmd, sc.robot.wheel_radius_m, sc.robot.track_m, &wl, &wr);
    d->ctrl[im.act_left] = wl;
    d->ctrl[im.act_right] = wr;
    mj_step2(m, d);
    // The IMU on its steps: kinematics and gyro of mj_step1, accelerometer of mj_step2, all of
    // the state at `step` (mj_step2 integrates qpos/qvel only).
    if (step >= im.start_step - im.imu_pre_roll_steps &&
        (step - im.start_step) % im.imu_every == 0) {
      ImuSample s;
      s.time_s = (step - im.start_step) * dt;
      s.has_gt = true;
      for (int i = 0; i < 3; ++i) {
        s.gyro_true_radps[i] = d->sensordata[im.gyro_adr + i];
        s.accel_true_mps2[i] = d->sensordata[im.accel_adr + i];
      }
      Eigen::Matrix3d R;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R(r, c) = d->site_xmat[9 * im.imu_site + 3 * r + c];
      s.T_world_imu.linear() = R;
      const mjtNum* p = d->site_xpos + 3 * im.imu_site;
      s.T_world_imu.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
      mjtNum vel[6];  // (angular, linear) at the site, world axes
      mj_objectVelocity(m, d, mjOBJ_SITE, im.imu_site, vel, 0);
      s.v_world_mps = Eigen::Vector3d(vel[3], vel[4], vel[5]);
      im.imu_noise->Apply(&s);
      im.imu_pending.push_back(s);
    }
    if (step >= last_step && have_gt && rendered == samples) break;
  }

  // Average the exposure samples, then the auto-exposure's gain (one for both cameras, from the
  // left image), then the per-image noise (seeded by frame and camera).
  for (int c = 0; c < 2; ++c) {
    acc[c] *= 1.0 / samples;
    if (sc.camera.distortion.any()) {  // the lens: the wide pinhole render remapped (bilinear)
      cv::Mat raw;
      cv::remap(acc[c], raw, im.lens.map_x, im.lens.map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      acc[c] = raw;
    }
  }
  if (im.auto_exposure) {
    const double gain = im.auto_exposure->Update(acc[0]);
    for (int c = 0; c < 2; ++c) acc[c] *= gain;
  }
  exposure_gain_ = im.auto_exposure ? im.auto_exposure->gain() : 1.0;
  for (int c = 0; c < 2; ++c) {
    cv::Mat out =
        ApplyCameraNoise(acc[c], sc.noise, DeriveSeed(sc.seed, static_cast<uint64_t>(k), c));
    (c == 0 ? frame->left : frame->right) = out;
  }
  if (sc.camera.distortion.any()) {  // depth along the same rays: nearest, never blended
    cv::Mat raw;
    cv::remap(frame->depth_m, raw, im.lens.map_x, im.lens.map_y, cv::INTER_NEAREST,
              cv::BORDER_REPLICATE);
    frame->depth_m = raw;
  }
  // The IMU samples up to the frame time (a blurred frame's exposure runs past it).
  frame->imu.clear();
  size_t taken = 0;
  while (taken < im.imu_pending.size() && im.imu_pending[taken].time_s <= t_frame + 0.5 * dt)
    frame->imu.push_back(im.imu_pending[taken++]);
  im.imu_pending.erase(im.imu_pending.begin(), im.imu_pending.begin() + taken);
  frame->index = k;
  frame->time_s = t_frame;
  ++im.next_frame;
  return true;
}

PlanarPose Simulator::BeliefAtLastFrame() const { return impl_->belief_at_frame; }

void Simulator::FixAtLastFrame(const PlanarPose& body) {
  Impl& im = *impl_;
  if (!im.closed_loop) return;
  PlanarPose belief = body;
  for (const DriveCommand& cmd : im.commands_since_frame)
    belief = DeadReckon(belief, cmd, scenario_.physics_dt_s);
  im.belief = belief;
  if (!im.nav.frames.empty()) {
    im.nav.frames.back().believed = body;
    im.nav.frames.back().fixed = true;
  }
}

void Simulator::SetStepEstimator(StepEstimator estimator) {
  impl_->step_estimator = std::move(estimator);
}

const NavigationReport& Simulator::navigation() const { return impl_->nav; }

}  // namespace sim
