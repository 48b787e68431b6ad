#!/usr/bin/env bash
# Suite throughput of issue #36 (README, "Suites, shards and regression checks"): the wall and
# CPU time (user + system, /usr/bin/time) of `vobench suite suites/ci.yaml -j 1` against one
# full `vobench run l_hallway`, for this build and a baseline binary (the previous main, built
# side by side with `git worktree`), back to back, ROUNDS times; prints one line per command.
#
#   results/speed/suite_throughput.sh BASELINE_VOBENCH [WORK_DIR]
#     BASELINE_VOBENCH  e.g. /tmp/base/build/vobench
#     WORK_DIR          output folders (default /tmp/vobench_throughput; replaced)
#   ROUNDS=2
set -euo pipefail
cd "$(dirname "$0")/../.."
base="${1:?usage: $0 BASELINE_VOBENCH [WORK_DIR]}"
work="${2:-/tmp/vobench_throughput}"
for round in $(seq 1 "${ROUNDS:-2}"); do
  for which in baseline this; do
    bin="$base"
    [ "$which" = this ] && bin="$PWD/build/vobench"
    rm -rf "$work/$which"
    mkdir -p "$work/$which"
    /usr/bin/time -f "$round $which suite ci -j 1: %e s wall, %U s user, %S s sys" \
      "$bin" suite suites/ci.yaml -j 1 -q --out "$work/$which/ci" >/dev/null
    /usr/bin/time -f "$round $which run l_hallway: %e s wall, %U s user, %S s sys" \
      "$bin" run l_hallway -q --out "$work/$which/run" >/dev/null
  done
done
