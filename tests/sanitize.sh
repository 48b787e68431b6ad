#!/usr/bin/env bash
# Sanitized checks (ASan + UBSan, leaks on) in build-asan/, separate from the Release build/.
#   tests/sanitize.sh          what .ci/run runs: the "vo" tests, the bad-input tests, one short
#                              `vobench run`, and (with clang) a fuzz smoke of every reader
#   tests/sanitize.sh --full   the whole ctest suite under the sanitizers (builds every test)
# With clang++ on PATH the build uses clang and also builds the libFuzzer targets
# (-DVOBENCH_FUZZ=ON); otherwise the default compiler, without fuzzers.
# Only what is run is built. Env: JOBS (parallel build/test jobs, default nproc).
set -euo pipefail
cd "$(dirname "$0")/.."
full=0
[[ "${1:-}" == "--full" ]] && full=1
jobs="${JOBS:-$(nproc)}"
build=build-asan

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# Leaks inside third-party libraries (named in the file), none in vobench's own code.
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0"

cfg=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1"
     -DVOBENCH_SANITIZE=address,undefined -DVOBENCH_BUILD_BENCHMARKS=OFF)
fuzz=0
# clang and its libFuzzer runtime (Debian 12: clang 14), installed when missing and we can.
if ! command -v clang++ > /dev/null || ! dpkg-query -W -f='${Status}' libclang-rt-14-dev 2>/dev/null | grep -q "install ok installed"; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && command -v sudo > /dev/null && SUDO=sudo
  if [ "$(id -u)" -eq 0 ] || [ -n "$SUDO" ]; then
    $SUDO apt-get update -q && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q \
      --no-install-recommends clang libclang-rt-14-dev || echo "sanitize: could not install clang"
  fi
fi
if command -v clang++ > /dev/null; then
  cfg+=(-DCMAKE_CXX_COMPILER=clang++ -DVOBENCH_FUZZ=ON)
  fuzz=1
else
  echo "sanitize: clang++ not found: building with the default compiler, no fuzz targets"
fi
mkdir -p "$build"
cmake -S . -B "$build" "${cfg[@]}" > "$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }

# Bad-input tests of the harness and sim suites (refused files, malformed datasets, CLI errors).
bad_input='^(CliTest|EurocMalformedTest|EvalBadInputTest|KittiMalformedTest|ReliabilityTest|RenderBadInputTest|ScenarioFileTest|VoConfigTest|YamlInputTest)\.'
# Left out here (they pass in the GCC Release build, also under valgrind): exact-number
# comparisons that fail in the clang -O1 sanitized build without any sanitizer report —
# Schur-LM vs Ceres to 1e-7 m per point, and RANSAC's pose at one seed within 2 mrad / 5 mm.
# See the README ("Tests").
fp_exact='^(BundleAdjustmentBackendTest\.SchurLmMatchesCeresWithNoiseAndOutliers|BundleAdjustmentBackendTest\.SchurLmMatchesCeresInOtherConfigurations|BundleAdjustmentBackendTest\.SchurLmMatchesCeresWithThePlanarPrior|RansacTest\.RecoversMotionWith40PercentOutliersAndHalfPixelNoise)$'
if ((full)); then
  cmake --build "$build" -j "$jobs"
  ctest --test-dir "$build" --output-on-failure -j "$jobs" -E "$fp_exact"
  exit 0
fi
targets=(vobench cli_test dataset_test eval_test reliability_test render_test run_test scenario_test yaml_input_test)
for t in tests/vo/*_test.cc; do targets+=("$(basename "$t" .cc)"); done
((fuzz)) && targets+=(fuzz)
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

ctest --test-dir "$build" --output-on-failure -j "$jobs" -L '^vo$' -E "$fp_exact"
ctest --test-dir "$build" --output-on-failure -j "$jobs" -R "$bad_input"

scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
"./$build/vobench" run l_hallway --max-frames 30 --no-plots -q --out "$scratch/run"
test -s "$scratch/run/metrics.json"
echo "sanitize: vobench run l_hallway (30 frames) ok"

if ((fuzz)); then
  tests/fuzz/smoke.sh "$build" 6
else
  echo "sanitize: fuzz smoke skipped (needs clang++)"
fi
