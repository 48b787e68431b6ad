#include "harness/suite/external.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <regex>
#include <thread>

#include "harness/dataset/euroc.h"
#include "harness/dataset/euroc_imu.h"
#include "harness/dataset/kitti.h"
#include "harness/dataset/writer.h"
#include "harness/interrupt.h"
#include "harness/output_folder.h"
#include "harness/render.h"
#include "harness/sequence_cache.h"
#include "harness/sim_adapter.h"
#include "harness/suite/child_process.h"
#include "harness/suite/folder.h"
#include "harness/trajectory_io.h"
#include "sim/simulator.h"

namespace harness {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

constexpr auto kPoll = std::chrono::milliseconds(20);  // polling period of the command
constexpr double kKillGraceS = 2.0;                    // SIGTERM -> SIGKILL

// argv with every placeholder replaced.
std::vector<std::string> Expand(const std::vector<std::string>& argv,
                                const std::vector<std::pair<std::string, std::string>>& values) {
  std::vector<std::string> out;
  for (std::string a : argv) {
    for (const auto& [key, value] : values)
      for (size_t p = a.find(key); p != std::string::npos; p = a.find(key, p + value.size()))
        a.replace(p, key.size(), value);
    out.push_back(a);
  }
  return out;
}

// What a shared sequence folder holds, in its name's hash: a folder written by a vobench that
// wrote other files (1: no IMU) is never taken for one of this version.
//   2: the IMU (mav0/imu0/, body.yaml, the ground truth at the IMU rate with the IMU as body)
constexpr int kSharedSequenceFormat = 2;

// The writer's options for the sequence of `scenario` seen at `stride`; EuRoC's body is the
// IMU (its pose on the robot's body T_body_imu), so the cameras' T_BS are relative to it.
DatasetWriter::Options SequenceWriterOptions(const sim::Scenario& scenario, int stride,
                                             const Eigen::Isometry3d& T_body_cam0,
                                             const Eigen::Isometry3d& T_body_imu) {
  DatasetWriter::Options options = ScenarioWriterOptions(scenario, T_body_cam0);
  options.format = DatasetFormat::kEuroc;
  options.rate_hz = scenario.rate_hz / stride;
  options.T_body_imu = T_body_imu;
  return options;
}

// The capture index (sim::StereoFrame::index) of each of the first `frames` frames the
// simulator gives: with frames.drop_rate the dropped ones are skipped (sim::Simulator::Next).
std::vector<int> CaptureIndices(const sim::Scenario& scenario, size_t frames) {
  std::vector<int> indices;
  for (int index = 0; indices.size() < frames; ++index)
    if (!sim::FrameFateOf(scenario.frames, scenario.seed, index).dropped) indices.push_back(index);
  return indices;
}

// The sequences of `spec` in the shared folder `datasets_dir`: the whole one (stride 1, one per
// scenario, seed and max_frames) simulated by the first run that needs it, and the run's strided
// copy of it; runs of other configurations find them written. One writer per folder at a time
// (a lock beside it; the others wait).
bool SharedSequence(const ExternalRunSpec& spec, const fs::path& datasets_dir, fs::path* dir,
                    std::string* error) {
  sim::Scenario scenario;
  if (!sim::LoadScenario(spec.scenario_path, &scenario, error)) return false;
  scenario.name.clear();  // the run's id: the configuration is not part of the sequence
  const fs::path full =
      datasets_dir /
      Fnv1aHex(sim::ScenarioToYaml(scenario) + "max_frames: " + std::to_string(spec.max_frames) +
               "\nshared_sequence_format: " + std::to_string(kSharedSequenceFormat) + "\n");
  std::error_code ec;
  fs::create_directories(datasets_dir, ec);
  {
    FolderLock lock;
    if (!LockSharedFolder(full.string(), &lock, error)) return false;
    ExternalRunSpec whole = spec;
    whole.stride = 1;
    if (!HasFolderMarker(full.string(), "dataset") && !WriteSequence(whole, full.string(), error))
      return false;
  }
  if (spec.stride == 1) {
    *dir = full;
    return true;
  }
  *dir = full.string() + "_k" + std::to_string(spec.stride);
  FolderLock lock;
  if (!LockSharedFolder(dir->string(), &lock, error)) return false;
  // The copy reads the KITTI side back: with raw frames (a lens, a rotated cam1) that side is
  // rectified, so such a sequence is simulated at its stride instead.
  return HasFolderMarker(dir->string(), "dataset") ||
         (ExportsRawFrames(scenario) ? WriteSequence(spec, dir->string(), error)
                                     : WriteStridedCopy(spec, full.string(), dir->string(), error));
}

bool CopyFile(const fs::path& from, const fs::path& to, std::string* error) {
  std::error_code ec;
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) *error = to.string() + ": cannot copy " + from.string() + ": " + ec.message();
  return !ec;
}

}  // namespace

bool WriteSequence(const ExternalRunSpec& spec, const std::string& dir, std::string* error) {
  sim::Scenario scenario;
  if (!sim::LoadScenario(spec.scenario_path, &scenario, error)) return false;
  std::unique_ptr<sim::Simulator> simulator = sim::Simulator::Create(scenario, error);
  if (!simulator) return false;
  DatasetWriter::Options options =
      SequenceWriterOptions(scenario, spec.stride, simulator->calibration().T_body_cam0,
                            simulator->calibration().T_body_imu);
  // A lens or a rotated cam1: {euroc} gets the raw frames, {dataset} them rectified (render's).
  auto rectification = std::make_shared<StereoRectification>();
  if (!ExportedRectification(scenario, simulator->calibration(), rectification.get(), error))
    return false;
  if (!rectification->IsIdentity()) options.rectification = rectification;
  DatasetWriter writer(options);
  if (!writer.Open(dir, ExportedStereoCamera(scenario, simulator->calibration()), error))
    return false;
  sim::StereoFrame frame;
  // The IMU samples of the frames skipped since the last frame kept: they go with the next one
  // kept (as the simulator's dropped frames' do), so imu0/ holds every sample up to the last
  // frame at any stride; the samples of frames after the last one kept are not written.
  std::vector<sim::ImuSample> carried;
  for (int index = 0; spec.max_frames == 0 || index < spec.max_frames; ++index) {
    if (!simulator->Next(&frame, error)) break;
    carried.insert(carried.end(), frame.imu.begin(), frame.imu.end());
    if (index % spec.stride == 0) {
      DatasetFrame dataset_frame = ToDatasetFrame(frame);
      dataset_frame.imu = std::move(carried);
      carried.clear();
      if (!writer.Add(dataset_frame, error)) return false;
    }
    if (InterruptSignal() != 0) {
      *error = InterruptedMessage(index, simulator->EstimatedFrames(), "frames", dir);
      return false;
    }
  }
  return error->empty() && writer.Finish(error);
}

bool WriteStridedCopy(const ExternalRunSpec& spec, const std::string& full_dir,
                      const std::string& dir, std::string* error) {
  sim::Scenario scenario;
  KittiReader reader;
  EurocCameraCalibration cam0;
  std::vector<int64_t> imu_ns;
  std::vector<sim::ImuSample> imu;
  const fs::path mav0 = fs::path(full_dir) / "mav0";
  if (!sim::LoadScenario(spec.scenario_path, &scenario, error) || !reader.Open(full_dir, error) ||
      !ReadEurocSensorYaml((mav0 / "cam0/sensor.yaml").string(), &cam0, error) ||
      !ReadEurocImu((mav0 / "imu0/data.csv").string(), &imu_ns, &imu, error) ||
      !ReadEurocImuGroundTruth((mav0 / "state_groundtruth_estimate0/data.csv").string(), imu_ns,
                               &imu, error))
    return false;
  // cam0's T_BS is relative to the IMU already (EuRoC's body): the IMU is the body here.
  const DatasetWriter::Options options =
      SequenceWriterOptions(scenario, spec.stride, cam0.T_body_cam, Eigen::Isometry3d::Identity());
  DatasetWriter writer(options);
  if (!writer.Open(dir, reader.camera(), error)) return false;
  // The samples on the simulator's clock (their stamps less the writer's offset), each with the
  // frame the simulator gave it: frame k (captured k-th) takes those up to k / rate_hz + half a
  // physics step (sim::Simulator); a frame kept takes those of the frames skipped before it.
  for (size_t i = 0; i < imu.size(); ++i)
    imu[i].time_s = static_cast<double>(imu_ns[i] - options.stamp_offset_ns) / 1e9;
  const std::vector<int> captured = CaptureIndices(scenario, reader.size());
  size_t next_sample = 0;
  DatasetFrame frame;
  for (size_t index = 0; index < reader.size(); index += static_cast<size_t>(spec.stride)) {
    if (!reader.ReadFrame(index, &frame, error)) return false;
    const double up_to_s = captured[index] / scenario.rate_hz + 0.5 * scenario.physics_dt_s;
    frame.imu.clear();
    while (next_sample < imu.size() && imu[next_sample].time_s <= up_to_s)
      frame.imu.push_back(imu[next_sample++]);
    if (!writer.Add(frame, error)) return false;
    if (InterruptSignal() != 0) {
      *error = InterruptedMessage(static_cast<int>(index), static_cast<int>(reader.size()),
                                  "frames", dir);
      return false;
    }
  }
  return writer.Finish(error);
}

const std::vector<std::string>& ExternalPlaceholders() {
  static const std::vector<std::string> kPlaceholders = {"{dataset}", "{euroc}", "{calib}",
                                                         "{out}"};
  return kPlaceholders;
}

bool CheckExternalEstimator(const ExternalEstimator& e, std::string* why) {
  if (e.command.empty() || e.command[0].empty()) {
    *why = "command: expected a list with the program first";
    return false;
  }
  static const std::regex kBrace("\\{[^{}]*\\}");
  for (size_t i = 0; i < e.command.size(); ++i) {
    const std::string& a = e.command[i];
    for (auto it = std::sregex_iterator(a.begin(), a.end(), kBrace); it != std::sregex_iterator();
         ++it) {
      const auto& known = ExternalPlaceholders();
      if (std::find(known.begin(), known.end(), it->str()) == known.end()) {
        *why = "command[" + std::to_string(i) + "]: unknown placeholder " + it->str() +
               " (expected {dataset}, {euroc}, {calib} or {out})";
        return false;
      }
    }
  }
  const fs::path t = e.trajectory;
  const std::string normal = t.lexically_normal().string();
  if (e.trajectory.empty() || t.is_absolute() || normal == "." || normal.rfind("..", 0) == 0) {
    *why = "trajectory: expected a file name relative to {out}, got '" + e.trajectory + "'";
    return false;
  }
  if (!(e.timeout_s > 0.0)) {
    *why = "timeout_s: expected seconds > 0";
    return false;
  }
  return true;
}

json ExternalEstimatorJson(const ExternalEstimator& e) {
  json j;
  j["command"] = e.command;
  j["trajectory"] = e.trajectory;
  j["format"] = ToString(e.format);
  j["timeout_s"] = e.timeout_s;
  return j;
}

json ExternalRunSpecJson(const ExternalRunSpec& spec) {
  json j;
  j["id"] = spec.id;
  j["scenario"] = spec.scenario_path;
  j["stride"] = spec.stride;
  j["max_frames"] = spec.max_frames;
  j["external"] = ExternalEstimatorJson(spec.estimator);
  return j;
}

bool ReadExternalRunSpec(const std::string& path, ExternalRunSpec* spec, std::string* error) {
  json j;
  if (!suite_internal::ReadJsonFile(path, &j, error)) return false;
  try {
    ExternalRunSpec s;
    s.id = j.at("id").get<std::string>();
    s.scenario_path = j.at("scenario").get<std::string>();
    s.stride = j.at("stride").get<int>();
    s.max_frames = j.at("max_frames").get<int>();
    const json& e = j.at("external");
    s.estimator.command = e.at("command").get<std::vector<std::string>>();
    s.estimator.trajectory = e.at("trajectory").get<std::string>();
    s.estimator.timeout_s = e.at("timeout_s").get<double>();
    if (!ParseTrajectoryFormat(e.at("format").get<std::string>(), &s.estimator.format))
      throw std::runtime_error("format: expected tum or kitti");
    std::string why;
    if (s.stride < 1 || s.max_frames < 0) throw std::runtime_error("stride or max_frames");
    if (!CheckExternalEstimator(s.estimator, &why)) throw std::runtime_error(why);
    *spec = s;
  } catch (const std::exception& ex) {
    *error = path + ": not an external run description (" + ex.what() + ")";
    return false;
  }
  return true;
}

// The launcher: a child forked before the simulator is loaded, so that the command it forks in
// turn starts from a small process. (A process's ru_maxrss keeps the high-water mark of the
// memory it had before exec; a command forked from this process after the simulator ran would
// report this process's ~140 MiB as its own peak.) The launcher reads the argv from one pipe
// (NUL-separated; end of file: start it, nothing: exit), writes the command's pid and then its
// wait status and ru_maxrss (KiB) to the other, as text lines. Only async-signal-safe calls
// after fork(): the buffers are static.
namespace {

constexpr size_t kArgvBytes = 1 << 16;
constexpr size_t kMaxArgs = 1024;
char launcher_buffer[kArgvBytes];
char* launcher_args[kMaxArgs + 1];

// Writes "<a> <b>\n" (non-negative numbers) without stdio.
void WriteNumbers(int fd, long a, long b) {
  char text[64];
  int n = 0;
  for (long v : {a, b}) {
    char digits[24];
    int k = 0;
    unsigned long u = v < 0 ? 0 : static_cast<unsigned long>(v);
    do {
      digits[k++] = static_cast<char>('0' + u % 10);
      u /= 10;
    } while (u > 0);
    while (k > 0) text[n++] = digits[--k];
    text[n++] = ' ';
  }
  text[n - 1] = '\n';
  (void)!write(fd, text, n);
}

[[noreturn]] void LauncherMain(int argv_fd, int result_fd) {
  size_t used = 0;
  for (;;) {
    const ssize_t r = read(argv_fd, launcher_buffer + used, kArgvBytes - 1 - used);
    if (r > 0) used += static_cast<size_t>(r);
    if (r == 0 || used >= kArgvBytes - 1) break;
    if (r < 0 && errno != EINTR) _exit(1);
  }
  if (used == 0) _exit(0);
  size_t count = 0;
  for (size_t i = 0; i < used && count < kMaxArgs; ++i) {
    launcher_args[count++] = launcher_buffer + i;
    while (i < used && launcher_buffer[i] != '\0') ++i;
  }
  launcher_args[count] = nullptr;
  const pid_t command = fork();
  if (command == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    close(result_fd);
    execvp(launcher_args[0], launcher_args);
    static const char kMessage[] = "vobench suite external: cannot start the command: ";
    const char* what = strerror(errno);
    (void)!write(STDERR_FILENO, kMessage, sizeof(kMessage) - 1);
    (void)!write(STDERR_FILENO, what, strlen(what));
    (void)!write(STDERR_FILENO, "\n", 1);
    _exit(127);
  }
  if (command < 0) _exit(1);
  setpgid(command, command);
  WriteNumbers(result_fd, command, 0);
  int status = 0;
  struct rusage usage;
  std::memset(&usage, 0, sizeof(usage));
  while (wait4(command, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  WriteNumbers(result_fd, status, usage.ru_maxrss);
  _exit(0);
}

// Reads "a b" lines from the launcher; false at end of file.
bool ReadNumbers(FILE* in, long* a, long* b) { return std::fscanf(in, "%ld %ld", a, b) == 2; }

}  // namespace

CommandLauncher::~CommandLauncher() {
  if (argv_fd_ >= 0) close(argv_fd_);  // end of file without an argv: the launcher exits
  if (result_ != nullptr) std::fclose(static_cast<FILE*>(result_));
  if (pid_ > 0) {
    int status = 0;
    waitpid(pid_, &status, 0);
  }
}

bool CommandLauncher::Start(std::string* error) {
  int to_launcher[2], from_launcher[2];
  if (pipe2(to_launcher, O_CLOEXEC) != 0 || pipe2(from_launcher, O_CLOEXEC) != 0) {
    *error = std::string("cannot make a pipe: ") + std::strerror(errno);
    return false;
  }
  const pid_t parent = getpid();
  sigset_t all, old_mask;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &old_mask);  // no handler runs in the child
  const pid_t child = fork();
  if (child == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(1);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    close(to_launcher[1]);
    close(from_launcher[0]);
    LauncherMain(to_launcher[0], from_launcher[1]);
  }
  const int fork_errno = errno;
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  close(to_launcher[0]);
  close(from_launcher[1]);
  if (child < 0) {
    close(to_launcher[1]);
    close(from_launcher[0]);
    *error = std::string("cannot start the command's launcher: ") + std::strerror(fork_errno);
    return false;
  }
  pid_ = child;
  argv_fd_ = to_launcher[1];
  result_ = fdopen(from_launcher[0], "r");
  return true;
}

bool CommandLauncher::Run(const std::vector<std::string>& argv, double timeout_s,
                          CommandOutcome* outcome, std::string* error) {
  *outcome = CommandOutcome();
  std::string packed;
  for (const auto& a : argv) packed += a + '\0';
  if (pid_ <= 0 || argv.empty() || packed.size() >= kArgvBytes - 1 || argv.size() > kMaxArgs) {
    *error = "cannot start the command: launcher not started or argv too long";
    return false;
  }
  const auto start = std::chrono::steady_clock::now();
  for (size_t off = 0; off < packed.size();) {
    const ssize_t w = write(argv_fd_, packed.data() + off, packed.size() - off);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      *error = std::string("cannot start the command: ") + std::strerror(errno);
      return false;
    }
    off += static_cast<size_t>(w);
  }
  close(argv_fd_);
  argv_fd_ = -1;
  FILE* in = static_cast<FILE*>(result_);
  long command = 0, unused = 0;
  if (!ReadNumbers(in, &command, &unused)) {
    *error = "cannot start the command: its launcher ended";
    return false;
  }
  // The launcher's report arrives when the command ends; meanwhile the clock and signals.
  const int fd = fileno(in);
  bool killed = false;
  double kill_time_s = 0.0;
  long status = 0, maxrss_kib = 0;
  for (;;) {
    struct pollfd p = {fd, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(kPoll.count()));
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (ready > 0) {
      if (!ReadNumbers(in, &status, &maxrss_kib)) {
        *error = "the command's launcher ended without a report";
        return false;
      }
      outcome->wall_s = elapsed;
      outcome->wait_status = static_cast<int>(status);
      outcome->peak_rss_mb = static_cast<double>(maxrss_kib) / 1024.0;  // KiB -> MiB
      break;
    }
    const bool interrupted = InterruptSignal() != 0;
    if (!killed && (elapsed > timeout_s || interrupted)) {
      kill(-static_cast<pid_t>(command), SIGTERM);
      killed = true;
      kill_time_s = elapsed;
      outcome->timed_out = !interrupted;
    } else if (killed && elapsed > kill_time_s + kKillGraceS) {
      kill(-static_cast<pid_t>(command), SIGKILL);
    }
  }
  kill(-static_cast<pid_t>(command), SIGKILL);  // what the command left running in its group
  if (InterruptSignal() != 0) {
    *error = "interrupted by signal " + std::to_string(InterruptSignal());
    return false;
  }
  return true;
}

bool RunExternalRun(const ExternalRunSpec& spec, const std::string& out_dir,
                    const std::string& datasets_dir, std::string* error) {
  const ExternalEstimator& e = spec.estimator;
  CommandLauncher launcher;  // before the simulator: see CommandLauncher
  if (!launcher.Start(error)) return false;
  OutputFolder folder;
  if (!folder.Create(out_dir, "run", error)) return false;
  const fs::path work = fs::absolute(folder.path());
  const fs::path estimate = work / "estimate";
  fs::path dataset = work / "dataset";
  int frames = 0;
  std::printf("external %s: the sequence (stride %d, max_frames %d)\n", spec.id.c_str(),
              spec.stride, spec.max_frames);
  std::fflush(stdout);
  if (!(datasets_dir.empty() ? WriteSequence(spec, dataset.string(), error)
                             : SharedSequence(spec, fs::absolute(datasets_dir), &dataset, error)))
    return false;
  std::vector<double> times;
  if (!ReadKittiTimes((dataset / "times.txt").string(), &times, error)) return false;
  frames = static_cast<int>(times.size());
  std::error_code ec;
  fs::create_directories(estimate, ec);
  if (ec) {
    *error = estimate.string() + ": cannot create: " + ec.message();
    return false;
  }
  const std::vector<std::string> argv =
      Expand(e.command, {{"{dataset}", dataset.string()},
                         {"{euroc}", dataset.string()},
                         {"{calib}", (dataset / "calib.txt").string()},
                         {"{out}", estimate.string()}});
  const std::string command_line = suite_internal::CommandLine(argv);
  std::printf("external %s: %d frames; running: %s\n", spec.id.c_str(), frames,
              command_line.c_str());
  std::fflush(stdout);
  CommandOutcome outcome;
  if (!launcher.Run(argv, e.timeout_s, &outcome, error)) return false;
  json info;
  info["command"] = e.command;  // as the suite file gives it
  info["argv"] = argv;          // as run (the paths are the work folder's, moved since)
  info["timeout_s"] = e.timeout_s;
  info["timed_out"] = outcome.timed_out;
  info["exit"] = outcome.timed_out ? "timed out" : suite_internal::ExitText(outcome.wait_status);
  info["wall_s"] = outcome.wall_s;
  info["peak_rss_mb"] = outcome.peak_rss_mb;
  std::printf("external %s: the command ended (%s) after %.2f s, peak memory %.1f MiB\n",
              spec.id.c_str(), info["exit"].get<std::string>().c_str(), outcome.wall_s,
              outcome.peak_rss_mb);
  std::fflush(stdout);
  if (outcome.timed_out) {
    *error = "the command timed out after " + FormatDouble(e.timeout_s) +
             " s (timeout_s): " + command_line;
    return false;
  }
  if (!WIFEXITED(outcome.wait_status) || WEXITSTATUS(outcome.wait_status) != 0) {
    *error = "the command failed (" + suite_internal::ExitText(outcome.wait_status) +
             "): " + command_line;
    return false;
  }
  const fs::path trajectory = estimate / e.trajectory;
  if (!fs::is_regular_file(trajectory)) {
    *error = trajectory.string() +
             ": the command wrote no trajectory there (trajectory: " + e.trajectory + ")";
    return false;
  }
  const bool tum = e.format == TrajectoryFormat::kTum;
  const std::string suffix = tum ? "_tum.txt" : "_kitti.txt";
  const fs::path gt = work / ("groundtruth" + suffix), est = work / ("trajectory" + suffix);
  if (!CopyFile(dataset / (tum ? "groundtruth_tum.txt" : "poses.txt"), gt, error) ||
      !CopyFile(trajectory, est, error))
    return false;
  ScoreOptions options;
  options.format = e.format;
  ScoreResult score;
  // Named after the command's file in the message, so the log says which file was bad.
  if (!ScoreTrajectory(spec.id, gt.string(), trajectory.string(), options, &score, error))
    return false;
  json metrics = json::parse(ScoreMetricsJson(score));
  metrics["frames"] = frames;
  metrics["frame_stride"] = spec.stride;
  metrics["command_wall_s"] = outcome.wall_s;
  metrics["command_peak_rss_mb"] = outcome.peak_rss_mb;
  if (datasets_dir.empty())
    fs::remove_all(dataset, ec);  // the images: the run folder keeps what was scored
  if (!WriteTextFile((work / "external.json").string(), info.dump(2) + "\n", error) ||
      !WriteTextFile((work / "metrics.json").string(), metrics.dump(2) + "\n", error))
    return false;
  return folder.Publish(error);
}

}  // namespace harness
