// The output folder of a suite (OUT) on disk: what is in it, its manifest, the stamps of
// finished runs and the leftovers of interrupted ones.
//
// Output folder (OUT), a marked folder of kind "suite" (harness/output_folder.h: an existing OUT
// without that marker is refused):
//   .vobench.json   the marker; .shard<i>of<N>.lock / .merge.lock while a call writes
//   suite.json      manifest: suite name, the shard, every run of the suite (id, axes, spec hash)
//   suite.yaml      copy of the suite file
//   specs/<id>.scenario.yaml, specs/<id>.vo.yaml
//                   effective inputs of each run (what the child reads); an external
//                   configuration's run has specs/<id>.external.json instead of .vo.yaml
//                   (suite/external.h)
//   runs/<id>/      finished run folders (`vobench run` layout + suite_run.json: spec hash,
//                   wall time). A run appears here only when finished: the child writes under
//                   tmp/shard<i>of<N>/<id>, the suite adds suite_run.json and renames it into
//                   runs/ (shards sharing one output folder keep out of each other's tmp/);
//                   an existing runs/<id> is replaced only when it is a marked run folder.
//   tmp/shard<i>of<N>/     the work folder of a call: its children's run folders, the
//                   sequences its runs share (sequences/: harness/sequence_cache.h; datasets/:
//                   external configurations); removed when the call ends
//   runs/<id>.failed.txt   a failed run: command, exit status, the tail of its log
//   logs/<id>.log   stdout and stderr of the child
//   summary.csv, summary.md, summary.png   the table across runs (written atomically)
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "harness/suite/spec.h"

namespace harness {

// Writes `text` to `path` through a temporary file and a rename (readers never see half a file).
bool WriteFileAtomically(const std::string& path, const std::string& text, std::string* error);

// The steps of the suite runner and its summary on the folder; not part of the suite API.
namespace suite_internal {

// The whole file as it is; *ok false (and what could be read) when it cannot be opened.
std::string ReadWholeFile(const std::filesystem::path& path, bool* ok);
// A JSON file; the error names the file.
bool ReadJsonFile(const std::filesystem::path& path, nlohmann::ordered_json* out,
                  std::string* error);

// suite.json: the suite's name and source, the shard, every run (index, id, axes, spec hash).
nlohmann::ordered_json Manifest(const Suite& suite, const std::vector<SuiteRun>& runs,
                                const Shard& shard);
// Runs listed in a manifest (DIR/suite.json), checked for the fields the summary needs.
bool ReadManifest(const std::filesystem::path& dir, std::string* name, std::vector<SuiteRun>* runs,
                  std::string* error);
// A folder that may become a suite output folder: absent, empty, or a marked suite folder
// (output_folder.h) of `name`; one without suite.json yet is being created by a shard started
// at the same time.
bool CheckOutDir(const std::filesystem::path& dir, const std::string& name, std::string* error);
// runs/, specs/ and logs/ under `out`.
bool MakeDirs(const std::filesystem::path& out, std::string* error);
// The run's effective inputs, as its child process reads them (specs/<id>.*.yaml).
bool WriteSpecs(const std::filesystem::path& out, const SuiteRun& r, std::string* error);

// A run folder finished for this spec: suite_run.json with the same hash (copied into *stamp
// when non-null), and metrics.json.
bool IsFinished(const std::filesystem::path& run_dir, const std::string& spec_hash,
                nlohmann::ordered_json* stamp = nullptr);

// The folder under tmp/ where this process's children write: one per shard, so shards that share
// an output folder never remove each other's runs in progress.
std::filesystem::path WorkDir(const std::filesystem::path& out, const std::string& tag);
// "shard<i>of<N>": names the shard's work folder and lock.
std::string ShardTag(const Shard& shard);
// Creates `work` (and tmp/), also while a shard sharing the folder removes an empty tmp/.
bool MakeWorkDir(const std::filesystem::path& work, std::string* error);
// Removes out/tmp/ when it is empty, never while another process is inside MakeWorkDir.
void RemoveEmptyTmp(const std::filesystem::path& out);
// Removes `work` (this process's folder under tmp/, and tmp/ when it is then empty) and every
// *.partial* entry in runs/: leftovers of interrupted runs.
void RemoveLeftovers(const std::filesystem::path& out, const std::filesystem::path& work);

}  // namespace suite_internal
}  // namespace harness
