#!/usr/bin/env bash
# Installs the Debian packages vobench needs (only those missing), then configures and builds
# it in Release under build/. Used by run.sh and test.sh; safe to run again.
# BUILD_TARGET=vobench builds only the command (and the libraries it links), not the tests and
# benchmarks: what run.sh needs; unset, everything is built (test.sh).
set -euo pipefail
cd "$(dirname "$0")"

PACKAGES=(
  build-essential cmake pkg-config git
  libmujoco-dev libosmesa6-dev          # simulator: physics + offscreen OpenGL
  libopencv-dev libeigen3-dev libceres-dev  # VO library
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libspdlog-dev  # config, CLI, JSON, logging
  libgtest-dev libgmock-dev libbenchmark-dev  # tests and benchmarks
  python3 python3-matplotlib python3-numpy    # plots in reports
  libnlopt-cxx-dev                            # derivative-free optimisers (vobench tune)
  parallel                                    # tests: the README's GNU-parallel shard recipe
  clang-format-14                             # tests/format_check.sh (the version it pins)
  librosbag-dev libsensor-msgs-dev libgeometry-msgs-dev  # --format rosbag (ROS 1 bags)
  pluginlib-dev libclass-loader-dev           # headers rosbag/bag.h includes (Debian 12)
  python3-rosbag python3-opencv               # tests: the exported bag read by Debian's rosbag
)
missing=()
for p in "${PACKAGES[@]}"; do
  [[ "$p" == \#* ]] && continue
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

JOBS="${JOBS:-$(nproc)}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@" > build.cmake.log 2>&1 || { cat build.cmake.log; exit 1; }
cmake --build build -j "$JOBS" ${BUILD_TARGET:+--target "$BUILD_TARGET"}
