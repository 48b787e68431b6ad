#include "harness/suite/folder.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "harness/output_folder.h"
#include "harness/path_names.h"
#include "harness/trajectory_io.h"

namespace harness {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

bool WriteFileAtomically(const std::string& path, const std::string& text, std::string* error) {
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  if (!WriteTextFile(tmp, text, error)) return false;  // removes tmp when it fails
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    *error = path + ": cannot write: " + ec.message();
    return false;
  }
  return true;
}

namespace suite_internal {

std::string ReadWholeFile(const fs::path& path, bool* ok) {
  std::ifstream in(path, std::ios::binary);
  *ok = static_cast<bool>(in);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

json Manifest(const Suite& suite, const std::vector<SuiteRun>& runs, const Shard& shard) {
  json j;
  j["suite"] = suite.name;
  j["source"] = suite.source_path;
  j["shard"] = std::to_string(shard.index) + "/" + std::to_string(shard.count);
  j["runs"] = json::array();
  for (const auto& r : runs) {
    json e;
    e["index"] = r.index;
    e["id"] = r.id;
    e["scenario"] = r.scenario;
    e["config"] = r.config;
    e["seed"] = r.seed;
    e["stride"] = r.stride;
    e["max_frames"] = r.max_frames;
    e["spec_hash"] = r.spec_hash;
    if (r.external) e["external"] = true;
    j["runs"].push_back(e);
  }
  return j;
}

bool ReadJsonFile(const fs::path& path, json* out, std::string* error) {
  bool ok = false;
  const std::string text = ReadWholeFile(path, &ok);
  if (!ok) {
    *error = path.string() + ": cannot read";
    return false;
  }
  try {
    *out = json::parse(text);
  } catch (const json::exception& e) {
    *error = path.string() + ": malformed JSON: " + e.what();
    return false;
  }
  return true;
}

bool ReadManifest(const fs::path& dir, std::string* name, std::vector<SuiteRun>* runs,
                  std::string* error) {
  json j;
  if (!ReadJsonFile(dir / "suite.json", &j, error)) return false;
  try {
    *name = j.at("suite").get<std::string>();
    runs->clear();
    for (const auto& e : j.at("runs")) {
      SuiteRun r;
      r.index = e.at("index").get<int>();
      r.id = e.at("id").get<std::string>();
      r.scenario = e.at("scenario").get<std::string>();
      r.config = e.at("config").get<std::string>();
      r.seed = e.at("seed").get<uint64_t>();
      r.stride = e.at("stride").get<int>();
      r.max_frames = e.at("max_frames").get<int>();
      r.spec_hash = e.at("spec_hash").get<std::string>();
      std::string why;
      if (r.index != static_cast<int>(runs->size()) ||
          !CheckRunIdPart(r.scenario, "scenario name", &why) ||
          !CheckRunIdPart(r.config, "configuration name", &why) ||
          !CheckPathName(r.id, "run id", &why))
        throw std::runtime_error("run " + r.id + " is out of order or malformed" +
                                 (why.empty() ? "" : ": " + why));
      runs->push_back(r);
    }
  } catch (const std::exception& e) {
    *error = (dir / "suite.json").string() + ": not a vobench suite manifest: " + e.what();
    return false;
  }
  return true;
}

bool CheckOutDir(const fs::path& dir, const std::string& name, std::string* error) {
  if (!CheckReplaceable(dir.string(), "suite", error)) return false;
  if (!fs::exists(dir / "suite.json")) return true;
  std::string other;
  std::vector<SuiteRun> runs;
  if (!ReadManifest(dir, &other, &runs, error)) return false;
  if (other != name) {
    *error =
        dir.string() + ": holds suite '" + other + "', not '" + name + "'; choose another --out";
    return false;
  }
  return true;
}

bool IsFinished(const fs::path& run_dir, const std::string& spec_hash, json* stamp) {
  if (!fs::is_regular_file(run_dir / "metrics.json")) return false;
  json j;
  std::string error;
  if (!ReadJsonFile(run_dir / "suite_run.json", &j, &error)) return false;
  if (!j.contains("spec_hash") || j["spec_hash"] != spec_hash) return false;
  if (stamp) *stamp = j;
  return true;
}

fs::path WorkDir(const fs::path& out, const std::string& tag) { return out / "tmp" / tag; }
std::string ShardTag(const Shard& shard) {
  return "shard" + std::to_string(shard.index) + "of" + std::to_string(shard.count);
}

namespace {

// Holds an flock on the output folder itself (Linux allows one on a directory) while tmp/ is made
// or removed, so that making tmp/<tag> and another shard's removing an empty tmp/ never interleave.
// Where the file system refuses the lock (some NFS mounts), it holds nothing and MakeWorkDir's
// retries cover that rare race.
class TmpLock {
 public:
  TmpLock(const fs::path& out, int operation)
      : fd_(::open(out.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)) {
    if (fd_ < 0) return;
    int rc;
    do rc = ::flock(fd_, operation);
    while (rc != 0 && errno == EINTR);
    if (rc != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  ~TmpLock() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the lock
  }
  TmpLock(const TmpLock&) = delete;
  TmpLock& operator=(const TmpLock&) = delete;

 private:
  int fd_;
};

}  // namespace

bool MakeWorkDir(const fs::path& work, std::string* error) {
  // Shards making their folders share the lock; a shard removing an empty tmp/ (RemoveEmptyTmp)
  // holds it alone. The retries are for file systems without flock.
  const TmpLock lock(work.parent_path().parent_path(), LOCK_SH);
  std::error_code ec;
  for (int attempt = 0; attempt < 100; ++attempt) {
    fs::create_directories(work, ec);
    if (!ec && fs::is_directory(work, ec)) return true;
  }
  *error = work.string() + ": cannot create: " + (ec ? ec.message() : "it keeps disappearing");
  return false;
}

void RemoveEmptyTmp(const fs::path& out) {
  const TmpLock lock(out, LOCK_EX);
  std::error_code ec;
  fs::remove(out / "tmp", ec);  // only if empty
}

void RemoveLeftovers(const fs::path& out, const fs::path& work) {
  std::error_code ec;
  fs::remove_all(work, ec);
  RemoveEmptyTmp(out);
  std::vector<fs::path> partial;  // only work folders of killed vobench processes
  for (fs::directory_iterator it(out / "runs", ec), end; !ec && it != end; it.increment(ec))
    if (IsStaleWorkFolder(it->path().string())) partial.push_back(it->path());
  for (const auto& p : partial) fs::remove_all(p, ec);
}

bool MakeDirs(const fs::path& out, std::string* error) {
  std::error_code ec;
  for (const char* sub : {"runs", "specs", "logs"}) {
    fs::create_directories(out / sub, ec);
    if (ec) {
      *error = (out / sub).string() + ": cannot create: " + ec.message();
      return false;
    }
  }
  return true;
}

bool WriteSpecs(const fs::path& out, const SuiteRun& r, std::string* error) {
  const fs::path scenario = out / "specs" / (r.id + ".scenario.yaml");
  if (!WriteFileAtomically(scenario.string(), r.scenario_yaml, error)) return false;
  if (!r.external)
    return WriteFileAtomically((out / "specs" / (r.id + ".vo.yaml")).string(), r.vo_yaml, error);
  ExternalRunSpec spec;
  spec.id = r.id;
  spec.scenario_path = scenario.string();
  spec.stride = r.stride;
  spec.max_frames = r.max_frames;
  spec.estimator = r.estimator;
  return WriteFileAtomically((out / "specs" / (r.id + ".external.json")).string(),
                             ExternalRunSpecJson(spec).dump(2) + "\n", error);
}

}  // namespace suite_internal
}  // namespace harness
