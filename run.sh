#!/usr/bin/env bash
# Quick start, command 1: install what is missing, build (Release), and run the main job:
# the L-hallway scenario end to end (simulate, run the VO, compare with ground truth),
# printing the metrics; the run folder with report.md and plots goes to out/l_hallway/.
set -euo pipefail
cd "$(dirname "$0")"
# Only the vobench command is built (the tests and benchmarks are test.sh's).
BUILD_TARGET=vobench ./setup.sh
./build/vobench run l_hallway --out out/l_hallway "$@"
