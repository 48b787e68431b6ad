#!/usr/bin/env bash
# Installs the build into a temporary prefix and runs the installed vobench from an unrelated
# folder: it must find its scenes, suites, plot scripts and baseline under
# <prefix>/share/vobench (sim/data_dir.h), not in the checkout it was built from.
# Usage: tests/gates/install_smoke.sh CMAKE_COMMAND BUILD_DIR
set -euo pipefail
cmake_cmd="$1"
build="$2"
t="$(mktemp -d)"
trap 'rm -rf "$t"' EXIT
prefix="$t/prefix"
"$cmake_cmd" --install "$build" --prefix "$prefix" > "$t/install.log" ||
  { cat "$t/install.log"; echo "FAIL: cmake --install $build --prefix $prefix"; exit 1; }

status=0
data="$prefix/share/vobench"
for f in bin/vobench share/vobench/scenes/l_hallway.yaml share/vobench/scenes/hallway_l.xml \
         share/vobench/scenes/robot_p2dx.xml share/vobench/suites/ci.yaml \
         share/vobench/harness/plots/plot.py share/vobench/harness/plots/suite_plot.py \
         share/vobench/harness/plots/tune_plot.py share/vobench/harness/plots/breakpoint_plot.py \
         share/vobench/results/baseline.json \
         include/vo/odometry.h; do
  [ -e "$prefix/$f" ] || { echo "FAIL: not installed: <prefix>/$f"; status=1; }
done
((status == 0)) || { echo "installed files:"; (cd "$prefix" && find . -type f | sort); exit 1; }

mkdir -p "$t/elsewhere"
cd "$t/elsewhere"
# A built-in scenario is looked up in the installed data folder (the message names it).
if "$prefix/bin/vobench" run no_such_scenario --no-plots --out x > no_such.log 2>&1; then
  echo "FAIL: vobench run no_such_scenario succeeded"; status=1
fi
grep -qF "$data/scenes" no_such.log ||
  { echo "FAIL: the installed vobench does not look in $data/scenes:"; cat no_such.log; status=1; }

"$prefix/bin/vobench" run l_hallway --max-frames 20 --no-plots --out run20 > run20.log 2>&1 ||
  { cat run20.log; echo "FAIL: installed vobench run l_hallway"; exit 1; }
for f in metrics.json trajectory_world_tum.txt per_frame.csv report.md; do
  [ -s "run20/$f" ] || { echo "FAIL: run20/$f not written"; status=1; }
done
# The plot scripts from the prefix (when matplotlib is there).
if /usr/bin/python3 -c 'import matplotlib' 2> /dev/null; then
  "$prefix/bin/vobench" run l_hallway --max-frames 6 --out run6 > run6.log 2>&1 ||
    { cat run6.log; echo "FAIL: installed vobench run l_hallway (with plots)"; exit 1; }
  if grep -q "plots not made" run6.log; then cat run6.log; echo "FAIL: plots not made"; status=1; fi
  for f in trajectory.png errors.png timing.png; do
    [ -s "run6/$f" ] || { echo "FAIL: run6/$f not written"; status=1; }
  done
else
  echo "install smoke: python3-matplotlib missing: plots from the prefix not checked"
fi
((status == 0)) && echo "install smoke: $prefix/bin/vobench ran l_hallway from $t/elsewhere with data from $data"
exit $status
