#include "harness/suite/runner.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <set>
#include <thread>

#include "harness/interrupt.h"
#include "harness/output_folder.h"
#include "harness/path_names.h"
#include "harness/progress.h"
#include "harness/suite/child_process.h"
#include "harness/suite/folder.h"
#include "harness/trajectory_io.h"

namespace harness {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using suite_internal::CheckOutDir;
using suite_internal::CommandLine;
using suite_internal::ExitText;
using suite_internal::IsFinished;
using suite_internal::MakeDirs;
using suite_internal::MakeWorkDir;
using suite_internal::Manifest;
using suite_internal::ReadJsonFile;
using suite_internal::ReadManifest;
using suite_internal::ReadWholeFile;
using suite_internal::RemoveLeftovers;
using suite_internal::ShardTag;
using suite_internal::Spawn;
using suite_internal::Tail;
using suite_internal::WorkDir;
using suite_internal::WriteSpecs;

constexpr int kFailedLogTailLines = 40;  // lines of the child's log kept in <id>.failed.txt
constexpr auto kWaitPoll = std::chrono::milliseconds(50);  // child-status polling period

struct Job {
  SuiteRun run;
  std::vector<std::string> argv;
  fs::path tmp;  // the child's --out (moved to runs/<id> when finished)
  std::chrono::steady_clock::time_point start;
};

// After a child ended: publish its run folder or record the failure.
bool FinishJob(const fs::path& out, const Job& job, int status, double wall_s, bool* ok,
               std::string* error) {
  const SuiteRun& r = job.run;
  const fs::path tmp = job.tmp, dst = out / "runs" / r.id;
  const fs::path failed = out / "runs" / (r.id + ".failed.txt");
  std::error_code ec;
  *ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && fs::is_regular_file(tmp / "metrics.json");
  if (*ok) {
    json stamp;
    stamp["id"] = r.id;
    stamp["index"] = r.index;
    stamp["spec_hash"] = r.spec_hash;
    stamp["scenario"] = r.scenario;
    stamp["config"] = r.config;
    stamp["seed"] = r.seed;
    stamp["stride"] = r.stride;
    stamp["max_frames"] = r.max_frames;
    stamp["wall_s"] = wall_s;
    stamp["command"] = CommandLine(job.argv);
    if (!WriteTextFile((tmp / "suite_run.json").string(), stamp.dump(2) + "\n", error))
      return false;
    // runs/<id> is replaced only when it is a vobench run folder (output_folder.h).
    if (!ReplaceFolder(tmp.string(), dst.string(), "run", error)) return false;
    fs::remove(failed, ec);
    return true;
  }
  fs::remove_all(tmp, ec);
  fs::remove_all(tmp.string() + ".partial", ec);
  std::string text =
      "run " + r.id + " failed: " + ExitText(status) +
      (WIFEXITED(status) && WEXITSTATUS(status) == 0 ? " but wrote no metrics.json" : "") + "\n";
  text += "command: " + CommandLine(job.argv) + "\n";
  text += "log: " + (out / "logs" / (r.id + ".log")).string() + "\n";
  text +=
      "--- last lines of the log ---\n" + Tail(out / "logs" / (r.id + ".log"), kFailedLogTailLines);
  return WriteFileAtomically(failed.string(), text, error);
}

std::vector<std::string> RunArgv(const std::string& binary, const fs::path& out,
                                 const fs::path& tmp, const SuiteRun& r, bool plots) {
  // The child of an external configuration (suite/external.h); the sequences it shares with
  // the other external runs of this call live in the shard's work folder beside tmp.
  if (r.external)
    return {
        binary,  "suite",      "external",   (out / "specs" / (r.id + ".external.json")).string(),
        "--out", tmp.string(), "--datasets", (tmp.parent_path() / "datasets").string(),
        "-q"};
  std::vector<std::string> argv = {binary,
                                   "run",
                                   (out / "specs" / (r.id + ".scenario.yaml")).string(),
                                   "--config",
                                   (out / "specs" / (r.id + ".vo.yaml")).string(),
                                   "--out",
                                   tmp.string(),
                                   "--max-frames",
                                   std::to_string(r.max_frames),
                                   "--stride",
                                   std::to_string(r.stride),
                                   "--sequence-cache",
                                   (tmp.parent_path() / "sequences").string(),
                                   "-q"};
  if (!plots) argv.push_back("--no-plots");
  return argv;
}

// The queue with the first run of each sequence (scenario, seed: the runs of all configurations
// and strides share its frames) first, the others after them, each part in suite order: with
// several jobs at once, the children simulate different sequences rather than wait on one.
std::deque<Job> FirstOfEachSequenceFirst(const std::deque<Job>& queue) {
  std::deque<Job> first, rest;
  std::set<std::pair<std::string, uint64_t>> seen;
  for (const Job& job : queue)
    (seen.insert({job.run.scenario, job.run.seed}).second ? first : rest).push_back(job);
  first.insert(first.end(), rest.begin(), rest.end());
  return first;
}

std::string SelfExecutable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("/proc/self/exe") : p.string();
}

}  // namespace

bool RunSuite(const Suite& suite, const SuiteOptions& options, SuiteResult* result,
              std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  *result = SuiteResult();
  if (options.jobs < 1) {
    *error = "-j: expected at least 1 job, got " + std::to_string(options.jobs);
    return false;
  }
  if (options.out_dir.empty()) {
    *error = "no output folder";
    return false;
  }
  const fs::path out = options.out_dir;
  const std::string shard_tag = ShardTag(options.shard);
  if (!CheckPathName(suite.name, "suite name", error) ||
      !CheckPathName(shard_tag, "shard tag", error))
    return false;
  const std::vector<SuiteRun> runs = ExpandSuite(suite);
  // The manifest first: a folder with suite.json is recognised as this suite's on resume.
  // A marked suite folder (created with its marker, or an earlier one of this suite), and the
  // lock of this shard in it: a second `suite` on the same folder and shard fails at once.
  FolderLock shard_lock;
  if (!CheckOutDir(out, suite.name, error) || !AdoptFolder(out.string(), "suite", error) ||
      !shard_lock.Acquire((out / ("." + shard_tag + ".lock")).string(),
                          out.string() + " (shard " + shard_tag + ")", error))
    return false;
  if (!WriteFileAtomically((out / "suite.json").string(),
                           Manifest(suite, runs, options.shard).dump(2) + "\n", error) ||
      !WriteFileAtomically((out / "suite.yaml").string(), suite.source_text, error) ||
      !MakeDirs(out, error))
    return false;
  const fs::path work = WorkDir(out, shard_tag);
  RemoveLeftovers(out, work);
  if (!MakeWorkDir(work, error)) return false;

  // What to run: this shard's runs that are not finished for their spec.
  std::deque<Job> queue;
  const std::string binary =
      options.vobench_binary.empty() ? SelfExecutable() : options.vobench_binary;
  for (const auto& r : runs) {
    if (!options.shard.Contains(r.index)) continue;
    if (!WriteSpecs(out, r, error)) return false;
    if (!options.force && IsFinished(out / "runs" / r.id, r.spec_hash)) {
      ++result->kept;
      continue;
    }
    queue.push_back({r, RunArgv(binary, out, work / r.id, r, options.run_plots), work / r.id, {}});
  }
  queue = FirstOfEachSequenceFirst(queue);
  const int total = static_cast<int>(queue.size());
  if (options.progress)
    std::fprintf(
        stderr,
        "suite %s: %d runs in this part, %d finished before (kept), %d to run, %d at once\n",
        suite.name.c_str(), total + result->kept, result->kept, total, options.jobs);

  ScopedInterruptHandlers interrupt_handlers;
  // A progress bar on a terminal; a line per finished run (with the ETA) in any case.
  const bool tty = isatty(STDERR_FILENO) != 0;
  Progress progress("suite " + suite.name, total, options.progress && tty);
  const auto runs_start = std::chrono::steady_clock::now();
  std::map<pid_t, Job> running;
  std::set<std::string> ran_now;
  int done = 0;
  bool fatal = false;
  while ((!queue.empty() || !running.empty()) && !fatal) {
    if (InterruptSignal() != 0) break;
    while (!queue.empty() && static_cast<int>(running.size()) < options.jobs) {
      Job job = queue.front();
      queue.pop_front();
      std::error_code ec;
      fs::remove_all(job.tmp, ec);
      fs::remove_all(job.tmp.string() + ".partial", ec);
      job.start = std::chrono::steady_clock::now();
      pid_t pid = 0;
      if (!Spawn(job.argv, (out / "logs" / (job.run.id + ".log")).string(), &pid, error)) {
        fatal = true;
        break;
      }
      running.emplace(pid, job);
    }
    int status = 0;
    // Poll our own children only (a host program may have others).
    auto it = running.begin();
    for (; it != running.end(); ++it)
      if (waitpid(it->first, &status, WNOHANG) == it->first) break;
    if (it == running.end()) {
      std::this_thread::sleep_for(kWaitPoll);
      continue;
    }
    const Job job = it->second;
    running.erase(it);
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - job.start).count();
    bool ok = false;
    if (!FinishJob(out, job, status, wall_s, &ok, error)) {
      fatal = true;
      break;
    }
    ++done;
    ran_now.insert(job.run.id);
    if (options.progress || !ok) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - runs_start).count();
      std::fprintf(
          stderr, "%s[%d/%d] %-6s %6.1f s  %s%s  (ETA %.0f s)\n",
          tty && options.progress ? "\r\033[K" : "", done, total, ok ? "ok" : "FAILED", wall_s,
          job.run.id.c_str(),
          ok ? "" : ("; see " + (out / "runs" / (job.run.id + ".failed.txt")).string()).c_str(),
          elapsed / done * (total - done));
    }
    progress.Update(done);
  }
  if (InterruptSignal() != 0 || fatal) {
    // Stop the children (their process groups: plots included); their unfinished folders under
    // tmp/ are removed (resume redoes them).
    for (const auto& [pid, job] : running) kill(-pid, SIGTERM);
    for (const auto& [pid, job] : running) {
      int status = 0;
      waitpid(pid, &status, 0);
    }
    RemoveLeftovers(out, work);
    if (!fatal)
      *error = std::string("interrupted by signal ") + std::to_string(InterruptSignal()) +
               " after " + std::to_string(done) + " of " + std::to_string(total) +
               " runs; the finished ones are kept: run the same command again to resume";
    return false;
  }
  progress.Finish(done);
  RemoveLeftovers(out, work);

  result->rows = CollectSuiteRows(out, runs, options.shard);
  for (auto& row : result->rows) {
    row.ran_now = ran_now.count(row.run.id) > 0;
    result->ran += row.ran_now && row.status == "ok";
  }
  CountFailedAndMissing(result);
  result->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return WriteSuiteSummary(out, suite.name, *result, error);
}

bool MergeSuiteShards(const std::vector<std::string>& shard_dirs, const std::string& out_dir,
                      SuiteResult* result, std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  *result = SuiteResult();
  if (shard_dirs.empty()) {
    *error = "merge: no shard folders given";
    return false;
  }
  std::string name;
  std::vector<SuiteRun> runs;
  for (size_t k = 0; k < shard_dirs.size(); ++k) {
    std::string n;
    std::vector<SuiteRun> r;
    if (!fs::exists(fs::path(shard_dirs[k]) / "suite.json")) {
      *error = shard_dirs[k] + ": not a vobench suite folder (no suite.json)";
      return false;
    }
    if (!ReadManifest(shard_dirs[k], &n, &r, error)) return false;
    std::error_code ec;
    if (fs::exists(out_dir) && fs::equivalent(shard_dirs[k], out_dir, ec)) {
      *error = out_dir + ": the merge output must not be one of the shard folders";
      return false;
    }
    // Nor inside one: a later merge or resume of that shard would read it as its own runs.
    const fs::path shard_path = fs::weakly_canonical(shard_dirs[k], ec);
    const fs::path out_path = fs::weakly_canonical(out_dir, ec);
    const auto [end, ignored] =
        std::mismatch(shard_path.begin(), shard_path.end(), out_path.begin(), out_path.end());
    if (!shard_path.empty() && end == shard_path.end()) {
      *error = out_dir + ": the merge output must not be inside the shard folder " + shard_dirs[k];
      return false;
    }
    if (k == 0) {
      name = n;
      runs = r;
      continue;
    }
    if (n != name) {
      *error = shard_dirs[k] + ": holds suite '" + n + "', but " + shard_dirs[0] + " holds '" +
               name + "'";
      return false;
    }
    if (r.size() != runs.size()) {
      *error = shard_dirs[k] + ": suite '" + n + "' has " + std::to_string(r.size()) +
               " runs there but " + std::to_string(runs.size()) + " in " + shard_dirs[0] +
               " (different suite files?)";
      return false;
    }
    for (size_t i = 0; i < r.size(); ++i)
      if (r[i].id != runs[i].id || r[i].spec_hash != runs[i].spec_hash) {
        *error = shard_dirs[k] + ": run " + std::to_string(i) + " is " + r[i].id + " (spec " +
                 r[i].spec_hash + ") but " + runs[i].id + " (spec " + runs[i].spec_hash + ") in " +
                 shard_dirs[0] + " (different suite files or inputs?)";
        return false;
      }
  }
  const fs::path out = out_dir;
  FolderLock merge_lock;
  if (!CheckOutDir(out, name, error) || !AdoptFolder(out.string(), "suite", error) ||
      !merge_lock.Acquire((out / ".merge.lock").string(), out.string() + " (merge)", error) ||
      !MakeDirs(out, error))
    return false;
  const fs::path work = WorkDir(out, "merge");
  RemoveLeftovers(out, work);
  for (const auto& r : runs) {
    std::error_code ec;
    const fs::path dst = out / "runs" / r.id;
    if (IsFinished(dst, r.spec_hash)) continue;
    for (const auto& dir : shard_dirs) {
      const fs::path src = fs::path(dir) / "runs" / r.id;
      if (!IsFinished(src, r.spec_hash)) continue;
      // Copy under tmp/ and rename, so a merged run also appears only when complete.
      const fs::path tmp = work / r.id;
      fs::remove_all(tmp, ec);
      fs::create_directories(work, ec);
      if (!ec) fs::copy(src, tmp, fs::copy_options::recursive, ec);
      if (ec) {
        *error = dst.string() + ": cannot copy the run from " + src.string() + ": " + ec.message();
        return false;
      }
      if (!ReplaceFolder(tmp.string(), dst.string(), "run", error)) return false;
      fs::remove(out / "runs" / (r.id + ".failed.txt"), ec);
      break;
    }
    for (const auto& dir : shard_dirs) {
      const fs::path failed = fs::path(dir) / "runs" / (r.id + ".failed.txt");
      if (!IsFinished(dst, r.spec_hash) && fs::exists(failed)) {
        fs::copy_file(failed, out / "runs" / (r.id + ".failed.txt"),
                      fs::copy_options::overwrite_existing, ec);
        break;
      }
    }
    // The inputs and the log go along, where the shard has them.
    for (const auto& dir : shard_dirs) {
      const fs::path specs = fs::path(dir) / "specs";
      if (!fs::exists(specs / (r.id + ".scenario.yaml"))) continue;
      for (const std::string& f :
           {r.id + ".scenario.yaml", r.id + ".vo.yaml", r.id + ".external.json"})
        if (fs::exists(specs / f))
          fs::copy_file(specs / f, out / "specs" / f, fs::copy_options::overwrite_existing, ec);
      if (fs::exists(fs::path(dir) / "logs" / (r.id + ".log")))
        fs::copy_file(fs::path(dir) / "logs" / (r.id + ".log"), out / "logs" / (r.id + ".log"),
                      fs::copy_options::overwrite_existing, ec);
      break;
    }
  }
  RemoveLeftovers(out, work);
  json manifest;
  if (!ReadJsonFile(fs::path(shard_dirs[0]) / "suite.json", &manifest, error)) return false;
  manifest["shard"] = "1/1";
  manifest["merged_from"] = shard_dirs;
  bool ok = false;
  const std::string suite_text = ReadWholeFile(fs::path(shard_dirs[0]) / "suite.yaml", &ok);
  if (!WriteFileAtomically((out / "suite.json").string(), manifest.dump(2) + "\n", error) ||
      (ok && !WriteFileAtomically((out / "suite.yaml").string(), suite_text, error)))
    return false;
  result->rows = CollectSuiteRows(out, runs, Shard());
  CountFailedAndMissing(result);
  result->kept = static_cast<int>(result->rows.size()) - result->failed - result->missing;
  result->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return WriteSuiteSummary(out, name, *result, error);
}

}  // namespace harness
