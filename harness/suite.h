// `vobench suite`: scenarios × VO configurations × noise seeds × frame strides, each run as a
// child `vobench run` process (at most `jobs` at once), resumable, splittable into shards, with
// a summary table across the runs. One header per part, all included here:
//
//   suite/spec.h      the suite file (LoadSuite), its runs (ExpandSuite: ids, spec hashes), shards
//   suite/folder.h    the suite's output folder: its layout, WriteFileAtomically
//   suite/runner.h    RunSuite (child processes, resume) and MergeSuiteShards
//   suite/summary.h   SuiteRow/SuiteResult, summary.csv/.md/.png, the printed table
//   suite/external.h  external configurations: another program's trajectory scored as a run
//
// (suite/child_process.h and the suite_internal parts of suite/folder.h are the runner's steps,
// not part of this API.)
#pragma once

#include "harness/suite/external.h"
#include "harness/suite/folder.h"
#include "harness/suite/runner.h"
#include "harness/suite/spec.h"
#include "harness/suite/summary.h"
