// The suite file and the runs it defines: reading and checking it (every scenario and VO
// configuration loaded, every override applied), expanding it into runs with their ids and spec
// hashes, and the shards that split the runs between processes.
//
// Suite file (YAML; unknown keys are refused with the file, line and key; see suites/*.yaml):
//   name: hallway               # suite name ([A-Za-z0-9_.-], no "__")
//   max_frames: 0               # optional default for every scenario (source frames, 0 = all)
//   scenarios:                  # at least one
//     - name: l_hallway         # optional (default: the scenario's name); unique
//       scenario: l_hallway     # a built-in scenario (scenes/) or a YAML file relative to
//                               # the suite file
//       set: {noise.pixel_sigma: 3}   # optional scenario overrides (dotted keys, overrides.h)
//       max_frames: 200         # optional: stop after this many source frames
//   configs:                    # at least one
//     - name: paper             # required, unique
//       config: vo.yaml         # optional VO config file relative to the suite file
//       set: {matcher.type: ncc_mutual}   # optional VO overrides, applied after `config`
//     - name: my_vo             # an external program instead of this VO (suite/external.h)
//       external: {command: [my_vo, "{dataset}", "{out}"], trajectory: traj_kitti.txt,
//                  format: kitti, timeout_s: 600}
//   seeds: [1, 2]               # optional noise seeds (default: each scenario's own seed)
//   strides: [1, 2]             # optional frame strides (default [1])
//
// Runs are the product scenarios × configs × seeds × strides in that nesting order (the stride
// varies fastest); run i (from 0) has the id `<scenario>__<config>__s<seed>__k<stride>`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "harness/suite/external.h"
#include "sim/scenario.h"
#include "vo/odometry.h"

namespace harness {

struct SuiteScenario {
  std::string name;        // id component
  sim::Scenario scenario;  // the base scenario with the suite's overrides applied
  int max_frames = 0;      // source frames per run (0 = all)
};

struct SuiteConfig {
  std::string name;             // id component
  vo::OdometryOptions options;  // effective VO options (built-in VO)
  bool external = false;        // an external program (`external:`) instead of this VO
  ExternalEstimator estimator;  // when external
};

struct Suite {
  std::string name;
  std::string source_path;  // the suite file ("" when parsed from text)
  std::string source_text;  // its text
  std::vector<SuiteScenario> scenarios;
  std::vector<SuiteConfig> configs;
  std::vector<uint64_t> seeds;  // empty: each scenario's own seed
  std::vector<int> strides = {1};
};

// Reads and checks a suite file: every scenario and config is loaded and every override applied
// here, so a bad suite fails before anything runs. Errors name the file, line and key.
bool LoadSuite(const std::string& path, Suite* suite, std::string* error);
// The same from text; relative paths are resolved against `base_dir`.
bool ParseSuite(const std::string& yaml_text, const std::string& source_name,
                const std::string& base_dir, Suite* suite, std::string* error);

// One run of a suite.
struct SuiteRun {
  int index = 0;                // position in the suite's fixed order, from 0
  std::string id;               // <scenario>__<config>__s<seed>__k<stride>
  std::string scenario;         // SuiteScenario::name
  std::string config;           // SuiteConfig::name
  uint64_t seed = 0;            // noise seed of the run
  int stride = 1;               // frame stride
  int max_frames = 0;           // source frames (0 = all)
  std::string scenario_yaml;    // effective scenario (named after the id), as the child reads it
  std::string vo_yaml;          // effective VO options, as the child reads them ("" external)
  bool external = false;        // an external configuration's run (suite/external.h)
  ExternalEstimator estimator;  // when external
  std::string spec_hash;        // 16 hex digits: FNV-1a over the inputs (portable: the scene file
                                // enters by name and content, not by absolute path)
};

// The runs of `suite` in their fixed order.
std::vector<SuiteRun> ExpandSuite(const Suite& suite);

// A part of a suite: shard i of n (1 <= i <= n) holds the runs whose index % n == i - 1.
struct Shard {
  int index = 1;
  int count = 1;
  bool Contains(int run_index) const { return run_index % count == index - 1; }
};
// Parses "i/N"; the error says what was expected.
bool ParseShard(const std::string& text, Shard* shard, std::string* error);

// A name that becomes part of a run id, and so of a folder name (CheckPathName, the one path
// rule) and of an unquoted summary.csv cell: also letters, digits, '_', '.', '-' only, and no
// "__" (the separator of the id's parts). False with *why naming `what` otherwise.
bool CheckRunIdPart(const std::string& name, const std::string& what, std::string* why);

// 64-bit FNV-1a of `text` as 16 hex digits (stable across machines and builds).
std::string Fnv1aHex(const std::string& text);

}  // namespace harness
