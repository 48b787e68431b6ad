#include "harness/output_folder.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)
#include <stdlib.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <thread>

#include "harness/trajectory_io.h"

#ifndef VOBENCH_VERSION
#define VOBENCH_VERSION "unknown"
#endif
#ifndef VOBENCH_GIT_DESCRIBE
#define VOBENCH_GIT_DESCRIBE ""
#endif

namespace harness {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kLockAttempts = 8;  // a lock file removed by its holder between open and flock

bool Fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

// "out/" -> "out", "a//b/" -> "a/b" (so "DIR.partial-*" and "DIR.vobench-lock" are siblings of
// DIR).
std::string NormalizeDir(const std::string& dir) {
  std::string s = fs::path(dir).lexically_normal().string();
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}

fs::path ParentOf(const std::string& dir) {
  const fs::path p(dir);
  return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

std::string HostName() {
  char name[256] = {};
  if (::gethostname(name, sizeof(name) - 1) != 0) return "";
  return name;
}

// argv of this process (/proc/self/cmdline: NUL-separated).
std::vector<std::string> CommandLine() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> argv;
  std::string arg;
  for (char c : text) {
    if (c == '\0') {
      argv.push_back(arg);
      arg.clear();
    } else {
      arg += c;
    }
  }
  if (!arg.empty()) argv.push_back(arg);
  return argv;
}

std::string NowUtc() {
  const std::time_t now = std::time(nullptr);
  std::tm tm = {};
  ::gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

bool IsEmptyFolder(const fs::path& dir) {
  std::error_code ec;
  return fs::is_empty(dir, ec) && !ec;
}

// A process of this host that no longer runs (a pid of another host means nothing here).
bool IsDeadHere(const FolderMarker& marker) {
  if (marker.pid <= 0 || marker.host != HostName()) return false;
  return ::kill(static_cast<pid_t>(marker.pid), 0) == -1 && errno == ESRCH;
}

// The pid in a work folder's name "<prefix><pid>-XXXXXX" (mkdtemp's six letters and digits);
// 0 when `entry` is not exactly such a name.
long WorkFolderPid(const std::string& entry, const std::string& prefix) {
  if (entry.size() <= prefix.size() + 7 || entry.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string rest = entry.substr(prefix.size());
  const size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || rest.size() - dash - 1 != 6 || dash > 10) return 0;
  long pid = 0;
  for (size_t i = 0; i < dash; ++i) {
    if (rest[i] < '0' || rest[i] > '9') return 0;
    pid = pid * 10 + (rest[i] - '0');
  }
  for (size_t i = dash + 1; i < rest.size(); ++i)
    if (!std::isalnum(static_cast<unsigned char>(rest[i]))) return 0;
  return pid;
}

// Removes the "DIR.partial-<pid>-XXXXXX" work folders that a vobench killed outright left behind
// (see IsStaleWorkFolder); anything else beside DIR is left alone.
void RemoveStaleWorkFolders(const std::string& dir) {
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(ParentOf(dir), ec), end; !ec && it != end; it.increment(ec))
    if (IsStaleWorkFolder(it->path().string(), fs::path(dir).filename().string()))
      stale.push_back(it->path());
  for (const fs::path& p : stale) fs::remove_all(p, ec);
}

// A unique folder "PREFIX<pid>-XXXXXX" (mkdtemp: created atomically, mode 0700 relaxed to the
// umask's default below).
bool MakeUniqueFolder(const std::string& prefix, std::string* path, std::string* error) {
  std::string pattern = prefix + std::to_string(::getpid()) + "-XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (::mkdtemp(buffer.data()) == nullptr)
    return Fail(error, pattern + ": cannot create the work folder: " + std::strerror(errno));
  *path = buffer.data();
  // mkdtemp makes 0700; an output folder gets the permissions of any other new folder.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  ::chmod(path->c_str(), 0777 & ~mask);
  return true;
}

const char* Article(const std::string& kind) {
  return (!kind.empty() && std::strchr("aeiou", kind[0]) != nullptr) ? "an" : "a";
}

}  // namespace

std::string VobenchVersion() {
  const std::string describe = VOBENCH_GIT_DESCRIBE;
  return std::string(VOBENCH_VERSION) + (describe.empty() ? "" : " (" + describe + ")");
}

bool IsStaleWorkFolder(const std::string& path, const std::string& name) {
  const fs::path p = fs::path(path).lexically_normal();
  const std::string entry = p.filename().string();
  const std::string tag = ".partial-";
  const size_t at = name.empty() ? entry.rfind(tag) : name.size();
  if (at == std::string::npos || (!name.empty() && entry.compare(0, at, name) != 0)) return false;
  const long name_pid = WorkFolderPid(entry, entry.substr(0, at) + tag);
  if (name_pid <= 0) return false;
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(p, ec))) return false;
  FolderMarker marker;
  return ReadFolderMarker(p.string(), &marker, nullptr) && marker.work_folder_of_pid == name_pid &&
         marker.pid == name_pid && IsDeadHere(marker);
}

bool WriteFolderMarker(const std::string& dir, const std::string& kind, std::string* error,
                       bool work_folder) {
  nlohmann::ordered_json j;  // in this order in the file
  j["vobench_folder"] = kFolderMarkerFormat;
  j["kind"] = kind;
  j["version"] = VobenchVersion();
  j["command"] = CommandLine();
  j["created_utc"] = NowUtc();
  j["pid"] = static_cast<long>(::getpid());
  j["host"] = HostName();
  if (work_folder) j[kWorkFolderKey] = static_cast<long>(::getpid());
  const fs::path path = fs::path(dir) / kFolderMarkerFile;
  const fs::path tmp =
      fs::path(dir) / (std::string(kFolderMarkerFile) + ".tmp-" + std::to_string(::getpid()));
  if (!WriteTextFile(tmp.string(), j.dump(2) + "\n", error)) return false;
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return Fail(error, path.string() + ": cannot write: " + ec.message());
  }
  return true;
}

bool ReadFolderMarker(const std::string& dir, FolderMarker* marker, std::string* error) {
  const fs::path path = fs::path(dir) / kFolderMarkerFile;
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(path, ec)))
    return Fail(error, path.string() + ": missing");
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    const json j = json::parse(text);
    FolderMarker m;
    m.format = j.at("vobench_folder").get<int>();
    m.kind = j.at("kind").get<std::string>();
    if (j.contains("version")) m.version = j["version"].get<std::string>();
    if (j.contains("command")) m.command = j["command"].get<std::vector<std::string>>();
    if (j.contains("created_utc")) m.created_utc = j["created_utc"].get<std::string>();
    if (j.contains("pid")) m.pid = j["pid"].get<long>();
    if (j.contains("host")) m.host = j["host"].get<std::string>();
    if (j.contains(kWorkFolderKey)) m.work_folder_of_pid = j[kWorkFolderKey].get<long>();
    if (m.kind.empty()) throw std::runtime_error("empty kind");
    *marker = m;
  } catch (const std::exception& e) {
    return Fail(error, path.string() + ": not a vobench folder marker (" + e.what() + ")");
  }
  return true;
}

bool HasFolderMarker(const std::string& dir, const std::string& kind) {
  FolderMarker marker;
  return ReadFolderMarker(dir, &marker, nullptr) && (kind.empty() || marker.kind == kind);
}

bool CheckReplaceable(const std::string& dir, const std::string& kind, std::string* error,
                      const std::string& option) {
  const std::string proceed = "; remove it yourself or choose another " + option;
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(dir, ec);
  if (!fs::exists(status)) return true;
  if (fs::is_symlink(status))
    return Fail(error, dir + ": is a symbolic link, not a folder vobench wrote" + proceed);
  if (!fs::is_directory(status)) return Fail(error, dir + ": exists and is not a folder" + proceed);
  if (IsEmptyFolder(dir)) return true;  // nothing in it to lose
  FolderMarker marker;
  std::string why;
  const fs::path marker_path = fs::path(dir) / kFolderMarkerFile;
  if (!fs::exists(fs::symlink_status(marker_path, ec)))
    return Fail(error, dir + ": exists and was not written by vobench (no " + kFolderMarkerFile +
                           "), so it is not a vobench " + kind + " folder" + proceed);
  if (!ReadFolderMarker(dir, &marker, &why))
    return Fail(error, why + "; not replacing " + dir + proceed);
  if (marker.kind != kind)
    return Fail(error, dir + ": holds " + Article(marker.kind) + " vobench " + marker.kind +
                           " folder (" + kFolderMarkerFile + " kind '" + marker.kind +
                           "'), not a vobench " + kind + " folder" + proceed);
  return true;
}

bool ReplaceFolder(const std::string& from, const std::string& to, const std::string& kind,
                   std::string* error) {
  if (!CheckReplaceable(to, kind, error)) return false;
  std::error_code ec;
  const bool replace = fs::exists(fs::symlink_status(to, ec)) && !IsEmptyFolder(to);
  if (!replace) {
    // Absent or empty: a plain rename (it replaces an empty folder atomically).
    if (::rename(from.c_str(), to.c_str()) == 0) return true;
    if (errno != ENOTEMPTY && errno != EEXIST)
      return Fail(error, to + ": cannot move " + from + " into place: " + std::strerror(errno));
    // Something appeared meanwhile: check it like any existing folder.
    if (!CheckReplaceable(to, kind, error)) return false;
  }
  // Swap the finished folder with the existing one atomically, then remove the old one.
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_EXCHANGE) == 0) {
    fs::remove_all(from, ec);
    return true;
  }
  if (errno != EINVAL && errno != ENOSYS && errno != ENOTSUP)
    return Fail(error, to + ": cannot replace it with " + from + ": " + std::strerror(errno));
  // A file system without RENAME_EXCHANGE: move the old folder aside, the new one in.
  std::string old_dir;
  if (!MakeUniqueFolder(to + ".old-", &old_dir, error)) return false;
  if (::rename(to.c_str(), old_dir.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    fs::remove(old_dir, ec);
    return Fail(error, to + ": cannot move the existing folder aside: " + why);
  }
  if (::rename(from.c_str(), to.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    ::rename(old_dir.c_str(), to.c_str());  // put the old one back
    return Fail(error, to + ": cannot move " + from + " into place: " + why);
  }
  fs::remove_all(old_dir, ec);
  return true;
}

bool AdoptFolder(const std::string& dir_arg, const std::string& kind, std::string* error) {
  const std::string dir = NormalizeDir(dir_arg);
  if (dir.empty()) return Fail(error, "empty output folder name");
  std::error_code ec;
  RemoveStaleWorkFolders(dir);  // of callers killed between creating and renaming
  for (int attempt = 0; attempt < kLockAttempts; ++attempt) {
    if (!CheckReplaceable(dir, kind, error)) return false;
    if (HasFolderMarker(dir, kind)) return true;
    // Absent or empty: a marked work folder renamed onto it, so the folder appears with its
    // marker (a concurrent caller's rename wins or loses as a whole).
    fs::create_directories(ParentOf(dir), ec);
    if (ec) return Fail(error, ParentOf(dir).string() + ": cannot create: " + ec.message());
    std::string work;
    if (!MakeUniqueFolder(dir + ".partial-", &work, error)) return false;
    if (!WriteFolderMarker(work, kind, error, /*work_folder=*/true)) {
      fs::remove_all(work, ec);
      return false;
    }
    const bool moved = ::rename(work.c_str(), dir.c_str()) == 0;
    const int rename_errno = errno;
    if (moved) return WriteFolderMarker(dir, kind, error);  // published: never a work folder
    fs::remove_all(work, ec);
    if (rename_errno != ENOTEMPTY && rename_errno != EEXIST)
      return Fail(error, dir + ": cannot create: " + std::strerror(rename_errno));
  }
  return Fail(error, dir + ": cannot create: it keeps changing");
}

// ---------------------------------------------------------------------------------------------
// FolderLock

namespace {

constexpr const char* kLockSignature = "vobench-lock pid=";

// A lock file is created (O_EXCL), locked, then written: another vobench may see it empty for
// a moment. An empty one is waited for (kEmptyLockWaits × kEmptyLockPoll, 2 s) before it counts
// as not vobench's (a user's empty file of that name is refused after that wait).
constexpr int kEmptyLockWaits = 200;
constexpr std::chrono::milliseconds kEmptyLockPoll{10};

bool IsEmptyFile(int fd) {
  struct stat st = {};
  return ::fstat(fd, &st) == 0 && st.st_size == 0;
}

// The pid in a lock file's text "vobench-lock pid=N host=H\n"; 0 when it is not such a text.
long LockHolder(int fd) {
  char buf[256] = {};
  const ssize_t n = ::pread(fd, buf, sizeof(buf) - 1, 0);
  const size_t sig = std::strlen(kLockSignature);
  if (n <= static_cast<ssize_t>(sig) || std::strncmp(buf, kLockSignature, sig) != 0) return 0;
  long pid = 0;
  for (size_t i = sig; i < static_cast<size_t>(n) && buf[i] >= '0' && buf[i] <= '9'; ++i)
    pid = pid * 10 + (buf[i] - '0');
  return pid;
}

}  // namespace

bool FolderLock::Acquire(const std::string& lock_path, const std::string& what,
                         std::string* error) {
  Release();
  const std::string not_ours = lock_path +
                               ": exists and is not a vobench lock file; remove it yourself or "
                               "choose another --out";
  int empty_waits = 0;
  for (int attempt = 0; attempt < kLockAttempts; ++attempt) {
    // Created exclusively: a file of that name that vobench did not create now is never written.
    int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0644);
    const bool created = fd >= 0;
    if (!created) {
      if (errno != EEXIST)
        return Fail(error, lock_path + ": cannot create the lock file: " + std::strerror(errno));
      fd = ::open(lock_path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
      if (fd < 0) {
        if (errno == ENOENT) continue;  // removed by its holder meanwhile
        if (errno == ELOOP) return Fail(error, not_ours);
        return Fail(error, lock_path + ": cannot open the lock file: " + std::strerror(errno));
      }
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int flock_errno = errno;
      const long holder = LockHolder(fd);
      const bool empty = IsEmptyFile(fd);
      ::close(fd);
      if (flock_errno != EWOULDBLOCK)
        return Fail(error, lock_path + ": cannot lock: " + std::strerror(flock_errno));
      if (holder <= 0 && empty && empty_waits < kEmptyLockWaits) {
        // Another vobench created and locked it and is writing its text now.
        ++empty_waits;
        --attempt;
        std::this_thread::sleep_for(kEmptyLockPoll);
        continue;
      }
      if (holder <= 0) return Fail(error, not_ours + " (another process holds a lock on it)");
      return Fail(error, what + ": another vobench (pid " + std::to_string(holder) +
                             ") is writing this folder; wait for it to end or choose another "
                             "--out");
    }
    // The holder before us may have removed the file after we opened it: then our lock is on a
    // file nobody else sees; open the path again.
    struct stat locked = {}, current = {};
    if (::fstat(fd, &locked) != 0 || ::stat(lock_path.c_str(), &current) != 0 ||
        locked.st_dev != current.st_dev || locked.st_ino != current.st_ino) {
      ::close(fd);
      continue;
    }
    if (!created) {
      // Nobody holds it. A lock file of a vobench killed outright (its own text, written by a
      // process that no longer holds it) is removed and created anew; anything else is kept.
      if (LockHolder(fd) <= 0) {
        const bool empty = IsEmptyFile(fd);
        ::close(fd);
        if (empty && empty_waits < kEmptyLockWaits) {
          // Another vobench created it and has not locked it yet (open, then flock).
          ++empty_waits;
          --attempt;
          std::this_thread::sleep_for(kEmptyLockPoll);
          continue;
        }
        return Fail(error, not_ours);
      }
      ::unlink(lock_path.c_str());  // while holding it: a concurrent opener re-checks the inode
      ::close(fd);
      continue;
    }
    const std::string text =
        std::string(kLockSignature) + std::to_string(::getpid()) + " host=" + HostName() + "\n";
    if (::pwrite(fd, text.data(), text.size(), 0) < 0) {
      // The lock holds without the text; only the message of a refused writer is poorer.
    }
    fd_ = fd;
    path_ = lock_path;
    return true;
  }
  return Fail(error, lock_path + ": cannot lock: the lock file keeps being replaced");
}

void FolderLock::Release() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // this process created it; while still holding it: see Acquire
  ::close(fd_);
  fd_ = -1;
  path_.clear();
}

// ---------------------------------------------------------------------------------------------
// OutputFolder

OutputFolder::~OutputFolder() { Discard(); }

void OutputFolder::Discard() {
  if (!published_ && !work_.empty()) {
    std::error_code ec;
    fs::remove_all(work_, ec);
    work_.clear();
  }
  lock_.Release();
}

bool OutputFolder::Create(const std::string& dir, const std::string& kind, const Options& options,
                          std::string* error) {
  if (!work_.empty() || published_) return Fail(error, "OutputFolder::Create: already used");
  dir_ = NormalizeDir(dir);
  kind_ = kind;
  options_ = options;
  if (dir_.empty()) return Fail(error, "empty output folder name");
  const std::string name = fs::path(dir_).filename().string();
  if (name.empty() || name == "." || name == "..")
    return Fail(error, dir + ": cannot be an output folder (name a folder of its own, e.g. " +
                           "out/run/NAME)");
  std::error_code ec;
  const fs::path parent = ParentOf(dir_);
  fs::create_directories(parent, ec);
  if (ec) return Fail(error, parent.string() + ": cannot create folder: " + ec.message());
  if (!lock_.Acquire(dir_ + kLockSuffix, dir_, error)) return false;

  // An existing DIR: refused unless it may be replaced (and replacing was asked for).
  if (fs::exists(fs::symlink_status(dir_, ec))) {
    if (!CheckReplaceable(dir_, kind_, error)) {
      lock_.Release();
      return false;
    }
    if (!options_.replace_existing) {
      lock_.Release();
      return Fail(error, dir_ + ": output folder already exists (" +
                             (options_.replace_flag.empty()
                                  ? "choose another --out"
                                  : "pass " + options_.replace_flag + " to replace it") +
                             ")");
    }
  }
  RemoveStaleWorkFolders(dir_);
  if (!MakeUniqueFolder(dir_ + ".partial-", &work_, error)) {
    lock_.Release();
    return false;
  }
  if (!WriteFolderMarker(work_, kind_, error, /*work_folder=*/true)) {  // the marker first
    Discard();
    return false;
  }
  return true;
}

bool OutputFolder::Publish(std::string* error) {
  if (work_.empty() || published_) return Fail(error, "OutputFolder::Publish: not created");
  std::error_code ec;
  if (!options_.replace_existing && fs::exists(fs::symlink_status(dir_, ec)))
    return Fail(error, dir_ + ": output folder appeared while writing (" +
                           (options_.replace_flag.empty()
                                ? "choose another --out"
                                : "pass " + options_.replace_flag + " to replace it") +
                           ")");
  // The published folder's marker no longer says "work folder" (nothing may remove it).
  if (!WriteFolderMarker(work_, kind_, error)) return false;
  if (!ReplaceFolder(work_, dir_, kind_, error)) return false;
  published_ = true;
  lock_.Release();
  return true;
}

}  // namespace harness
