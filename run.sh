#!/usr/bin/env bash
# Quick start, command 1: install what is missing, build (Release), and run the main job:
# the L-hallway scenario end to end. Output goes to out/l_hallway/.
set -euo pipefail
cd "$(dirname "$0")"
./setup.sh
./build/vobench render l_hallway --out out/l_hallway --overwrite "$@"
