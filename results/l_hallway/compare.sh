#!/usr/bin/env bash
# Runs the L-hallway scenario with each configuration in configs/ and writes comparison.md
# and comparison.csv here. Usage (from the repository root, after ./setup.sh):
#   results/l_hallway/compare.sh [build/vobench]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
vobench="${1:-build/vobench}"
out="${OUT:-out/compare}"
csv="$here/comparison.csv"
echo "config,end_pose_error_m,end_pose_error_pct,ate_rmse_m,drift_pct,lost_frames,vo_ms_median,vo_ms_p95" > "$csv"
for cfg in paper no_ba ba3 ba10 matcher_svd_ncc matcher_ncc_mutual matcher_lucas_kanade fast_no_lr_check stereobm_two_pass range_0_5m dense_disparity ba_ceres; do
  "$vobench" run l_hallway --config "$here/configs/$cfg.yaml" --out "$out/$cfg" -q --no-plots > /dev/null
  /usr/bin/python3 - "$out/$cfg/metrics.json" "$cfg" >> "$csv" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
print(",".join([sys.argv[2]] + [str(round(m[k], 4)) for k in
      ("end_pose_error_m", "end_pose_error_pct", "ate_rmse_m", "drift_pct", "lost_frames", "vo_ms_median", "vo_ms_p95")]))
PY
  echo "done: $cfg"
done
/usr/bin/python3 - "$csv" > "$here/comparison.md" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("| configuration | end-pose error (m) | end-pose error (%) | ATE RMSE (m) | drift (%) | lost frames | VO ms/frame median | p95 |")
print("| --- | --- | --- | --- | --- | --- | --- | --- |")
for r in rows:
    print("| {config} | {end_pose_error_m} | {end_pose_error_pct} | {ate_rmse_m} | {drift_pct} | {lost_frames} | {vo_ms_median} | {vo_ms_p95} |".format(**r))
PY
cat "$here/comparison.md"
