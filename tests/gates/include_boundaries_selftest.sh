#!/usr/bin/env bash
# Self-test of include_boundaries.sh: a small tree with one include of each kind that is refused
# must fail and name each file:line; the same tree without them must pass.
set -euo pipefail
gate="$(cd "$(dirname "$0")" && pwd)/include_boundaries.sh"
t="$(mktemp -d)"
trap 'rm -rf "$t"' EXIT
mkdir -p "$t/vo" "$t/sim" "$t/harness"
printf '#include "vo/camera.h"\n#include <opencv2/core.hpp>\n' > "$t/vo/camera.cc"
printf '#include "sim/scenario.h"\n' > "$t/sim/scenario.cc"
printf '#include "vo/camera.h"\n#include "sim/scenario.h"\n#include "harness/run.h"\n' > "$t/harness/run.cc"
"$gate" "$t" > "$t/clean.log" || { cat "$t/clean.log"; echo "FAIL: a clean tree was refused"; exit 1; }

printf '#include "vo/camera.h"\n#include "sim/scenario.h"\n#include <mujoco/mujoco.h>\n' > "$t/vo/bad.cc"
printf '#include "sim/scenario.h"\n#include "harness/run.h"\n#include "vo/camera.h"\n' > "$t/sim/bad.h"
printf '  #  include "../vo/camera.h"\n' > "$t/harness/bad.cc"
if "$gate" "$t" > "$t/bad.log"; then cat "$t/bad.log"; echo "FAIL: bad includes passed"; exit 1; fi
cat "$t/bad.log"
for want in 'vo/bad.cc:2: includes "sim/scenario.h"' 'vo/bad.cc:3: includes "mujoco/mujoco.h"' \
            'sim/bad.h:2: includes "harness/run.h"' 'sim/bad.h:3: includes "vo/camera.h"' \
            'harness/bad.cc:1: includes "../vo/camera.h"' '5 include(s) against'; do
  grep -qF "$want" "$t/bad.log" || { echo "FAIL: expected a line with: $want"; exit 1; }
done
echo "include boundaries self-test: ok"
