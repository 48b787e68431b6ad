#!/usr/bin/env bash
# Speed figures of issue #10 (results/speed/summary.md): the VO's median time per frame and its
# per-stage medians (metrics.json) at four camera sizes, on frames the simulator renders once:
#   hallway  320x240,  fovy 55°,   baseline 0.09 m  (scenes/l_hallway.yaml as it is)
#   vga      640x480,  fovy 55°,   baseline 0.09 m
#   euroc    752x480,  fovy 55.3°, baseline 0.11 m  (fx ≈ 458 px, EuRoC-like)
#   kitti    1241x376, fovy 29.3°, baseline 0.54 m  (fx ≈ 718 px, KITTI-like)
# Each run reads the same KITTI-layout folder (vobench run --dataset), single-threaded, pinned
# to one core (taskset). With a second binary (the previous main, built side by side with
# `git worktree`), both run back to back on the same frames, alternating, and the table gives
# both figures and their ratio (absolute times drift on a shared machine; the ratio does not).
#
#   results/speed/measure.sh [BASELINE_VOBENCH] [WORK_DIR]
#     BASELINE_VOBENCH  e.g. /tmp/base/build/vobench (optional)
#     WORK_DIR          rendered frames and run folders (default /tmp/vobench_speed)
#   REPEATS=3 (runs per binary and size; the table takes the median), FRAMES=200 (frames per
#   run, 0 = all), CORE=1 (the core to pin to), BENCH=1 (also run the Google benchmarks into
#   results/speed/bench_*.json)
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
NEW="$ROOT/build/vobench"
BASE="${1:-}"
WORK="${2:-/tmp/vobench_speed}"
REPEATS="${REPEATS:-3}"
FRAMES="${FRAMES:-200}"
CORE="${CORE:-1}"
[ -x "$NEW" ] || { echo "measure: build first (./setup.sh)" >&2; exit 1; }
[ -z "$BASE" ] || [ -x "$BASE" ] || { echo "measure: $BASE is not an executable" >&2; exit 1; }
mkdir -p "$WORK"

source "$ROOT/results/speed/variants.sh"
variant hallway 320 240 55 0.09
variant vga 640 480 55 0.09
variant euroc 752 480 55.3 0.11
variant kitti 1241 376 29.3 0.54

run() {  # binary label size repeat
  local out="$WORK/runs/$2_$3_$4"
  rm -rf "$out"
  /usr/bin/time -f "%M" -o "$out.rss" taskset -c "$CORE" "$1" run --dataset "$WORK/ds_$3" \
    --max-frames "$FRAMES" --out "$out" --no-plots -q > /dev/null
}
mkdir -p "$WORK/runs"
for size in hallway vga euroc kitti; do
  for r in $(seq 1 "$REPEATS"); do
    echo "run $size $r/$REPEATS"
    run "$NEW" new "$size" "$r"
    [ -z "$BASE" ] || run "$BASE" base "$size" "$r"
  done
done

/usr/bin/python3 - "$WORK/runs" "$REPEATS" "$BASE" "$FRAMES" <<'EOF'
import json, os, statistics, subprocess, sys, datetime, platform
runs, repeats, base, frames = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
sizes = [("hallway", "320x240"), ("vga", "640x480"), ("euroc", "752x480"), ("kitti", "1241x376")]
stages = ["disparity", "detect", "depth", "match", "predict", "guided", "motion", "ba"]
def load(label, size):
    ms, st, rss, acc = [], {k: [] for k in stages}, [], None
    for r in range(1, repeats + 1):
        d = f"{runs}/{label}_{size}_{r}"
        if not os.path.exists(f"{d}/metrics.json"): continue
        m = json.load(open(f"{d}/metrics.json"))
        ms.append(m["vo_ms_median"])
        for k in stages: st[k].append(m["stage_ms_median"].get(k, 0.0))
        rss.append(int(open(f"{d}.rss").read().split()[-1]) / 1024.0)
        acc = m
    if not ms: return None
    return {"ms": statistics.median(ms), "stages": {k: statistics.median(v) for k, v in st.items()},
            "rss": max(rss), "end": acc["end_pose_error_pct"], "lost": acc["lost_frames"],
            "ate": acc["ate_rmse_m"]}
cpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
model = next((l.split(":", 1)[1].strip() for l in cpu.splitlines() if l.startswith("Model name")), platform.processor())
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True).stdout.strip()
out = ["# Speed: median VO time per frame (ms), Release, one thread, one pinned core", "",
       f"Machine: {model}, {os.cpu_count()} cores. Commit {commit}{' (with uncommitted changes)' if dirty else ''}, "
       f"{datetime.date.today().isoformat()}. Frames: the first {frames} of each rendered L-hallway sequence "
       f"(`results/speed/measure.sh`), median over {repeats} runs.", ""]
hdr = "| frames | vobench | per stage (ms) | end-pose error | lost | peak RSS |"
if base:
    hdr = "| frames | vobench | previous main | ratio | per stage now (ms) | per stage before (ms) | end-pose error now / before | lost now / before | peak RSS now / before (MiB) |"
out += [hdr, "|" + "---|" * (hdr.count("|") - 1)]
csv = ["size,label,vo_ms_median," + ",".join(f"{k}_ms" for k in stages) + ",end_pose_error_pct,lost_frames,peak_rss_mib"]
fmt = lambda s: ", ".join(f"{k} {s['stages'][k]:.2f}" for k in stages if s["stages"][k] >= 0.005)
for size, res in sizes:
    n, b = load("new", size), load("base", size) if base else None
    if n is None: continue
    for label, s in (("new", n), ("base", b)):
        if s: csv.append(f"{res},{label},{s['ms']:.4f}," + ",".join(f"{s['stages'][k]:.4f}" for k in stages) + f",{s['end']:.4f},{s['lost']},{s['rss']:.1f}")
    if b:
        out.append(f"| {res} | **{n['ms']:.2f}** | {b['ms']:.2f} | **{n['ms'] / b['ms']:.2f}** | {fmt(n)} | {fmt(b)} | "
                   f"{n['end']:.2f} % / {b['end']:.2f} % | {n['lost']} / {b['lost']} | {n['rss']:.0f} / {b['rss']:.0f} |")
    else:
        out.append(f"| {res} | **{n['ms']:.2f}** | {fmt(n)} | {n['end']:.2f} % | {n['lost']} | {n['rss']:.0f} MiB |")
here = os.path.join(os.getcwd(), "results", "speed")
open(f"{here}/summary.md", "w").write("\n".join(out) + "\n")
open(f"{here}/summary.csv", "w").write("\n".join(csv) + "\n")
print("\n".join(out))
EOF

if [ "${BENCH:-0}" = 1 ]; then
  for b in frontend_bench backend_bench odometry_bench; do
    taskset -c "$CORE" "$ROOT/build/tests/$b" --benchmark_out="$ROOT/results/speed/bench_${b%_bench}.json" \
      --benchmark_out_format=json > /dev/null
  done
fi
