#!/usr/bin/env bash
# Quick start, command 2: install what is missing, build (Release), run the whole test suite.
# Tests that need OpenGL (OSMesa) carry the ctest label "gl"; run the rest with: ctest -LE gl
set -euo pipefail
cd "$(dirname "$0")"
BUILD_TARGET= ./setup.sh  # everything: the command, the tests, the benchmarks
ctest --test-dir build --output-on-failure -j "${JOBS:-$(nproc)}" "$@"
