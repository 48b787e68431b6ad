#!/usr/bin/env bash
# Makes again every committed figure that depends on the default VO, after a change of a
# default (a change that keeps every trajectory bit for bit needs none of this: check that with
# `vobench check` and the suites' byte-identical metrics instead). Accuracy figures are
# deterministic: two calls of this script give the same bytes but the timings.
#
#   results/regen.sh [PART...]     (from anywhere; after ./setup.sh)
#     PART: main compare suites check tune closed_loop breakpoint gyro robustness
#           (default: all of them, in that order; speed figures are separate, see below)
#   JOBS=2 (parallel runs where a command takes -j), WORK=/tmp/vobench_regen (run folders)
#
# Not made here: the speed figures, which need an idle machine and the previous main built
# beside this one (results/speed/measure.sh, results/speed/viso2/measure.sh with BASE=...), and
# the real datasets' figures (`vobench eval`, README "Real datasets"), which need ../shared.
# Every figure's command is the README's; this script only runs them in one go.
# Run so far (2026-12-07, on a trial default that was not kept): main, suites, check and gyro;
# compare, closed_loop, breakpoint, tune and robustness are the README's commands, not yet run
# through this script: check their output against the committed files the first time.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BIN="${BIN:-$ROOT/build/vobench}"
JOBS="${JOBS:-2}"
WORK="${WORK:-/tmp/vobench_regen}"
[ -x "$BIN" ] || { echo "regen: build first (./setup.sh)" >&2; exit 1; }
mkdir -p "$WORK"
parts=("$@")
[ ${#parts[@]} -gt 0 ] || parts=(main compare suites check tune closed_loop breakpoint gyro robustness)

step() { echo "== $(date -u +%H:%M:%S) $*"; }

# A suite's summary files into results/<dir>/.
suite() {  # suite-file results-dir
  rm -rf "$WORK/suite_$(basename "$1" .yaml)"
  "$BIN" suite "$1" -j "$JOBS" -q --out "$WORK/suite_$(basename "$1" .yaml)" > /dev/null
  mkdir -p "$2"
  for f in summary.md summary.csv summary.png; do
    [ ! -f "$WORK/suite_$(basename "$1" .yaml)/$f" ] || cp "$WORK/suite_$(basename "$1" .yaml)/$f" "$2/"
  done
}

for part in "${parts[@]}"; do
  case "$part" in
    main)
      step "vobench run l_hallway -> results/l_hallway"
      rm -rf "$WORK/l_hallway"
      "$BIN" run l_hallway --out "$WORK/l_hallway" -q > /dev/null
      for f in report.md metrics.json per_frame.csv vo_options.yaml scenario.yaml trajectory.png \
               errors.png timing.png frame_000100.png trajectory_kitti.txt groundtruth_kitti.txt \
               trajectory_world_tum.txt groundtruth_world_tum.txt estimate_in_gt_world_tum.txt; do
        [ ! -f "$WORK/l_hallway/$f" ] || cp "$WORK/l_hallway/$f" results/l_hallway/
      done
      ;;
    compare)
      step "results/l_hallway/compare.sh"
      OUT="$WORK/compare" results/l_hallway/compare.sh "$BIN" > /dev/null
      ;;
    suites)
      for s in hallway buildings realism; do
        step "vobench suite suites/$s.yaml"
        suite "suites/$s.yaml" "results/suites/$s"
      done
      ;;
    check)
      step "vobench check --update"
      "$BIN" check --update -j "$JOBS" -q --out "$WORK/check" > /dev/null
      ;;
    tune)
      step "vobench tune suites/tune_matcher.yaml"
      rm -rf "$WORK/tune"
      "$BIN" tune suites/tune_matcher.yaml --out "$WORK/tune" -q > /dev/null
      for f in "$WORK"/tune/*; do [ ! -f "$f" ] || cp "$f" results/tune/; done
      ;;
    closed_loop)
      step "closed loop (results/closed_loop/)"
      cfg=results/closed_loop/free.yaml
      for k in 1 3 5 10; do
        "$BIN" run l_hallway --config $cfg --stride $k --out "$WORK/cl/l_open_k$k" -q --no-plots > /dev/null &
        "$BIN" run scenes/l_hallway_closed_loop.yaml --config $cfg --stride $k \
          --out "$WORK/cl/l_closed_k$k" -q > /dev/null
        wait
      done
      "$BIN" run l_hallway --out "$WORK/cl/l_open_vehicle" -q --no-plots > /dev/null &
      "$BIN" run scenes/l_hallway_closed_loop.yaml --out "$WORK/cl/l_closed_vehicle" -q > /dev/null
      wait
      for k in 1 5 10; do
        "$BIN" run office_floor --config $cfg --stride $k --out "$WORK/cl/o_open_k$k" -q --no-plots > /dev/null &
        "$BIN" run scenes/office_floor_closed_loop.yaml --config $cfg --stride $k \
          --out "$WORK/cl/o_closed_k$k" -q > /dev/null
        wait
      done
      "$BIN" run results/closed_loop/office_floor/open_loop_baseline10.yaml --config $cfg \
        --out "$WORK/cl/o_open_b10" -q --no-plots > /dev/null &
      "$BIN" run results/closed_loop/office_floor/closed_loop_baseline10.yaml --config $cfg \
        --out "$WORK/cl/o_closed_b10" -q > /dev/null
      wait
      cp "$WORK/cl/l_closed_k1/metrics.json" "$WORK/cl/l_closed_k1/navigation.csv" \
         "$WORK/cl/l_closed_k1/trajectory.png" results/closed_loop/
      cp "$WORK/cl/o_closed_k1/metrics.json" "$WORK/cl/o_closed_k1/navigation.csv" \
         "$WORK/cl/o_closed_k1/trajectory.png" results/closed_loop/office_floor/
      cp "$WORK/cl/o_closed_b10/metrics.json" results/closed_loop/office_floor/metrics_baseline10.json
      cp "$WORK/cl/o_closed_b10/navigation.csv" results/closed_loop/office_floor/navigation_baseline10.csv
      cp "$WORK/cl/o_closed_b10/trajectory.png" results/closed_loop/office_floor/trajectory_baseline10.png
      /usr/bin/python3 - "$WORK/cl" <<'PY'
import json, os, sys
d = sys.argv[1]
for name in sorted(os.listdir(d)):
    m = json.load(open(f"{d}/{name}/metrics.json"))
    nav = {k: m.get(k) for k in ("end_error_m", "max_waypoint_error_m", "wall_contacts", "wall_contact_s", "reached_goal")}
    print(f"{name}: end-pose {m['end_pose_error_m']:.3f} m ({m['end_pose_error_pct']:.2f} %), "
          f"ATE {m['ate_rmse_m']:.3f} m, lost {m['lost_frames']}, {nav}")
PY
      ;;
    breakpoint)
      bp=results/breakpoint
      step "breakpoints (results/breakpoint/)"
      args=(--until 'end_pose_error_pct>2' -q)
      rm -rf "$bp"/l_hallway_pixel_sigma "$bp"/l_hallway_pixel_sigma_metric_only "$bp"/l_hallway_pixel_sigma_3seeds \
             "$bp"/l_hallway_turn_rate "$bp"/l_hallway_noisy_turn_rate
      "$BIN" breakpoint l_hallway --vary noise.pixel_sigma --range 0,20 "${args[@]}" \
        --out "$bp/l_hallway_pixel_sigma" > /dev/null &
      "$BIN" breakpoint l_hallway --vary noise.pixel_sigma --range 0,20 "${args[@]}" --max-lost-frames -1 \
        --out "$bp/l_hallway_pixel_sigma_metric_only" > /dev/null
      wait
      "$BIN" breakpoint l_hallway --vary noise.pixel_sigma --range 0,20 "${args[@]}" --seeds 3 \
        --aggregate worst --out "$bp/l_hallway_pixel_sigma_3seeds" > /dev/null &
      "$BIN" breakpoint l_hallway --vary robot.turn_rate_dps --range 30,360 "${args[@]}" \
        --out "$bp/l_hallway_turn_rate" > /dev/null
      "$BIN" breakpoint "$bp/l_hallway_noisy.yaml" --vary robot.turn_rate_dps --range 10,120 --scan 6 \
        "${args[@]}" --out "$bp/l_hallway_noisy_turn_rate" > /dev/null
      wait
      rm -rf "$bp"/*/points
      ;;
    gyro)
      for s in free_direct_suite free_direct_heldout_suite vehicle_sweep_suite; do
        step "vobench suite results/gyro_prior/$s.yaml"
        suite "results/gyro_prior/$s.yaml" "$WORK/gyro_prior_$s"
        echo "   summary: $WORK/gyro_prior_$s/summary.md"
      done
      ;;
    robustness)
      step "results/robustness/sweep.sh"
      BIN="$BIN" JOBS="$JOBS" results/robustness/sweep.sh "$WORK/robustness" > /dev/null
      ;;
    *) echo "regen: unknown part '$part' (main compare suites check tune closed_loop breakpoint gyro robustness)" >&2; exit 2 ;;
  esac
done
step "done"
