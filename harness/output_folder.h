// Ownership of output folders (issue #11): vobench replaces only what it can prove it wrote.
//
// Every output folder vobench creates carries a marker file, DIR/.vobench.json, written first:
//   {"vobench_folder": 1, "kind": "run", "version": "0.1.0 (g8493cb3)",
//    "command": ["vobench", "run", "--out", "m"], "created_utc": "2026-12-01T21:46:24Z",
//    "pid": 4242, "host": "node1"}
// `kind` says what the folder is: "run" (run, eval), "dataset" (render), "tune", "suite"
// (suite, suite merge, check), "match-eval", "score", "breakpoint", "sequence" (sequence_cache.h).
// Before vobench replaces a folder (a re-run, render --overwrite, a suite's runs/<id>) or writes
// into one (a suite resumes), the folder must be absent, empty, or hold a marker of the same kind;
// anything else is refused with
//   "DIR: exists and was not written by vobench (no .vobench.json), so it is not a vobench run
//    folder; remove it yourself or choose another --out"
// Folders of vobench versions before the marker have none and are refused the same way.
//
// A work folder's marker also says whose work folder it is: "work_folder_of_pid": P. Publishing
// rewrites the marker without it, so a finished folder (and any copy or renamed backup of one:
// `mv r r.old-1`, `cp -a r r.partial-1-abcdef`) never looks like a work folder.
//
// Concurrency: a writer holds an exclusive flock(2) on the lock file "DIR.vobench-lock" beside
// DIR (in DIR's parent) from Create() until it is done, so a second writer of the same DIR fails
// at once with "DIR: another vobench (pid N) is writing this folder". The lock file sits beside
// DIR, not inside it, because DIR does not exist at the start and is replaced by a rename at the
// end; one file per name keeps writers of sibling folders independent. The lock file is created
// exclusively (O_EXCL) and holds "vobench-lock pid=N host=H"; a file of that name that vobench
// did not create is never written, truncated nor removed (refused instead), so a user's own
// "DIR.lock" (`flock DIR.lock vobench run --out DIR`) is none of vobench's business. The kernel
// drops the lock when its process dies (also on SIGKILL); the holder removes the file when done,
// and a lock file of a killed vobench (its text, nobody holding it) is removed and created anew.
//
// Work folders are unique per process, "DIR.partial-<pid>-<random>" (mkdtemp). Create() removes
// stale ones of DIR left by processes killed outright, and only those: the exact name
// DIR.partial-<pid>-XXXXXX, a marker saying "work folder of pid <pid>" (the same pid), of this
// host, and that process no longer runs (IsStaleWorkFolder). Nothing else is ever removed: not a
// published folder, not "DIR.old-*", not a folder without a marker.
#pragma once

#include <string>
#include <vector>

namespace harness {

constexpr const char* kFolderMarkerFile = ".vobench.json";
constexpr int kFolderMarkerFormat = 1;  // "vobench_folder" field of the marker
constexpr const char* kWorkFolderKey = "work_folder_of_pid";  // marker key of a work folder only
constexpr const char* kLockSuffix = ".vobench-lock";          // DIR's lock file: DIR + this

// The contents of a marker file.
struct FolderMarker {
  int format = kFolderMarkerFormat;  // marker layout version
  std::string kind;                  // "run", "dataset", "tune", "suite", "match-eval",
                                     // "score", "breakpoint"
  std::string version;               // vobench version (CMake project version and git describe)
  std::vector<std::string> command;  // the command line that wrote the folder (argv)
  std::string created_utc;           // ISO 8601, seconds, UTC ("2026-12-01T21:46:24Z")
  long pid = 0;                      // the writing process
  std::string host;                  // its host name (pids mean something only there)
  long work_folder_of_pid = 0;       // > 0: an unpublished work folder of this pid
};

// "0.1.0 (g8493cb3)": the version written into markers.
std::string VobenchVersion();

// Writes DIR/.vobench.json for `kind` (this process, now) through a temporary file and a rename;
// `work_folder`: marked as this process's unpublished work folder.
bool WriteFolderMarker(const std::string& dir, const std::string& kind, std::string* error,
                       bool work_folder = false);
// Reads DIR/.vobench.json. False when it is missing (*error says so) or malformed.
bool ReadFolderMarker(const std::string& dir, FolderMarker* marker, std::string* error);

// Whether vobench may replace DIR (or write into it) as a folder of `kind`: DIR absent, an empty
// folder, or one holding a marker of `kind`. Otherwise false and *error is the refusal, naming
// DIR and how to proceed (`option`: the flag that names the folder, "--out").
bool CheckReplaceable(const std::string& dir, const std::string& kind, std::string* error,
                      const std::string& option = "--out");

// Moves folder `from` to `to` (same file system), replacing `to` only when CheckReplaceable(to,
// kind) allows; the swap is atomic (renameat2 RENAME_EXCHANGE where the file system has it), so
// `to` is never missing, and the replaced folder is removed afterwards.
bool ReplaceFolder(const std::string& from, const std::string& to, const std::string& kind,
                   std::string* error);

// Makes DIR a marked folder of `kind` that is written in place (a suite folder, resumed by
// later calls): an absent or empty DIR becomes one atomically (a marked work folder renamed
// onto it; concurrent callers agree on one); a DIR with a marker of `kind` is kept as it is;
// anything else is refused as by CheckReplaceable.
bool AdoptFolder(const std::string& dir, const std::string& kind, std::string* error);

// True for a work folder that a vobench killed outright left behind, the only kind of folder
// vobench removes without being asked: named exactly "<name>.partial-<pid>-XXXXXX" (`name`
// empty: any name), a folder (not a link), its marker saying "work folder of pid <pid>", of this
// host, and that process no longer runs.
bool IsStaleWorkFolder(const std::string& path, const std::string& name = "");

// True for a folder holding a readable marker (of any kind when `kind` is empty).
bool HasFolderMarker(const std::string& dir, const std::string& kind = "");

// An exclusive, non-blocking flock(2) on a lock file, held for the object's lifetime. The file
// holds the holder's pid (for the message of the one refused) and is removed on release.
class FolderLock {
 public:
  FolderLock() = default;
  ~FolderLock() { Release(); }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

  // Locks `lock_path` (created when missing). When another process (or another FolderLock of
  // this one) holds it: false, *error = "<what>: another vobench (pid N) is writing this
  // folder; wait for it to end or choose another --out".
  bool Acquire(const std::string& lock_path, const std::string& what, std::string* error);
  void Release();
  bool held() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
  std::string path_;
};

// An output folder written as a marked work folder "DIR.partial-<pid>-<random>" and moved to DIR
// only by Publish(), under the lock "DIR.vobench-lock". Destroying it before Publish() (an error,
// an exception, SIGINT/SIGTERM seen by the command: harness/interrupt.h) removes the work folder,
// so a half-written DIR never exists.
//
// Usage:  OutputFolder folder;
//         if (!folder.Create(dir, "run", error)) return false;
//         ... write files under folder.path() ...
//         if (!folder.Publish(error)) return false;
class OutputFolder {
 public:
  struct Options {
    bool replace_existing = true;  // replace an existing DIR of this kind on Publish(); false:
                                   // refuse any existing DIR (render without --overwrite)
    std::string replace_flag;      // the option that allows replacing, for the refusal
                                   // ("--overwrite"); empty: none
  };

  OutputFolder() = default;
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  // Locks DIR, checks an existing DIR (CheckReplaceable, or refused outright when
  // !options.replace_existing), creates DIR's parent folders, removes stale marked work folders
  // of DIR and creates this one with its marker. Errors name the folder.
  bool Create(const std::string& dir, const std::string& kind, std::string* error) {
    return Create(dir, kind, Options(), error);
  }
  bool Create(const std::string& dir, const std::string& kind, const Options& options,
              std::string* error);
  const std::string& path() const { return work_; }  // the work folder; empty before Create()
  const std::string& dir() const { return dir_; }    // DIR (normalised: no trailing '/')
  // Moves the work folder to DIR (ReplaceFolder; checked again) and releases the lock.
  bool Publish(std::string* error);
  // Removes the work folder now (as the destructor does) and releases the lock.
  void Discard();
  bool published() const { return published_; }

 private:
  Options options_;
  std::string dir_, kind_, work_;
  FolderLock lock_;
  bool published_ = false;
};

}  // namespace harness
