#!/usr/bin/env bash
# Issue #35 point 3: the VO's median time per frame against libviso2's (VisualOdometryStereo,
# default parameters) on the same rendered frames, one pinned core, back to back, alternating.
# libviso2 is built here from a copy of its public source (github.com/srv/viso2) for measuring
# only; nothing of vobench's build or tests needs it.
#
#   results/speed/viso2/measure.sh VISO2 [WORK_DIR]
#     VISO2     a checkout of srv/viso2, or its git directory (a fetched snapshot)
#     WORK_DIR  rendered frames, the libviso2 build and the runs (default /tmp/vobench_viso2)
#   REPEATS=5 (runs per program and size; the table takes the median of the runs' medians),
#   FRAMES=0 (frames per run, 0 = all), CORE=1 (the core to pin to), BASE=path (a second
#   vobench, e.g. the previous main built with `git worktree`: measured the same way)
# Writes results/speed/viso2.md and results/speed/viso2.csv.
set -euo pipefail
cd "$(dirname "$0")/../../.."
ROOT=$(pwd)
NEW="$ROOT/build/vobench"
VISO2="${1:?usage: results/speed/viso2/measure.sh VISO2_CHECKOUT_OR_GIT_DIR [WORK_DIR]}"
WORK="${2:-/tmp/vobench_viso2}"
REPEATS="${REPEATS:-5}"
FRAMES="${FRAMES:-0}"
CORE="${CORE:-1}"
BASE="${BASE:-}"
[ -x "$NEW" ] || { echo "measure: build first (./setup.sh)" >&2; exit 1; }
[ -z "$BASE" ] || [ -x "$BASE" ] || { echo "measure: BASE=$BASE is not an executable" >&2; exit 1; }
mkdir -p "$WORK/src" "$WORK/runs"

# libviso2's sources (its CMakeLists: Release, -msse3), with the driver beside this script.
if [ -d "$VISO2/libviso2/libviso2/src" ]; then
  SRC="$VISO2/libviso2/libviso2/src"
else
  git --git-dir="$VISO2" archive HEAD libviso2/libviso2/src | tar -x -C "$WORK/src"
  SRC="$WORK/src/libviso2/libviso2/src"
fi
echo "building libviso2 from $SRC"
g++ -std=c++14 -O3 -DNDEBUG -msse3 -w -I"$SRC" "$SRC"/filter.cpp "$SRC"/matcher.cpp \
  "$SRC"/matrix.cpp "$SRC"/reconstruction.cpp "$SRC"/triangle.cpp "$SRC"/viso.cpp \
  "$SRC"/viso_stereo.cpp results/speed/viso2/viso2_kitti.cc \
  $(pkg-config --cflags --libs opencv4) -o "$WORK/viso2_kitti"

# The frames: scenes/l_hallway.yaml as it is (320x240) and at KITTI's size (as
# results/speed/measure.sh renders them).
source "$ROOT/results/speed/variants.sh"
variant hallway 320 240 55 0.09
variant kitti 1241 376 29.3 0.54

for size in hallway kitti; do
  for r in $(seq 1 "$REPEATS"); do
    echo "run $size $r/$REPEATS"
    out="$WORK/runs/viso2_${size}_$r"; rm -rf "$out"; mkdir -p "$out"
    taskset -c "$CORE" "$WORK/viso2_kitti" "$WORK/ds_$size" "$out" "$FRAMES" > "$out/summary.txt"
    out="$WORK/runs/new_${size}_$r"; rm -rf "$out"
    taskset -c "$CORE" "$NEW" run --dataset "$WORK/ds_$size" --max-frames "$FRAMES" --out "$out" --no-plots -q > /dev/null
    if [ -n "$BASE" ]; then
      out="$WORK/runs/base_${size}_$r"; rm -rf "$out"
      taskset -c "$CORE" "$BASE" run --dataset "$WORK/ds_$size" --max-frames "$FRAMES" --out "$out" --no-plots -q > /dev/null
    fi
  done
done

/usr/bin/python3 - "$WORK/runs" "$REPEATS" "$BASE" <<'PY'
import json, os, statistics, subprocess, sys, datetime, platform
runs, repeats, base = sys.argv[1], int(sys.argv[2]), sys.argv[3]
def vobench(label, size):
    v = [json.load(open(f"{runs}/{label}_{size}_{r}/metrics.json"))["vo_ms_median"]
         for r in range(1, repeats + 1) if os.path.exists(f"{runs}/{label}_{size}_{r}/metrics.json")]
    return statistics.median(v) if v else None
def viso2(size):
    v = []
    for r in range(1, repeats + 1):
        t = [float(x) for x in open(f"{runs}/viso2_{size}_{r}/times_ms.txt").read().split()][1:]
        v.append(statistics.median(t))
    return statistics.median(v)
def accuracy(size):  # the first run's (both programs are deterministic)
    m = json.load(open(f"{runs}/new_{size}_1/metrics.json"))
    failed = open(f"{runs}/viso2_{size}_1/summary.txt").read().split()[3]
    return f"{m['lost_frames']} lost, end {m['end_pose_error_pct']:.2f} % | {failed} failed |"
cpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
model = next((l.split(":", 1)[1].strip() for l in cpu.splitlines() if l.startswith("Model name")), platform.processor())
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
if subprocess.run(["git", "status", "--porcelain", "--", "vo", "harness", "sim", "CMakeLists.txt"],
                  capture_output=True, text=True).stdout.strip():
    commit += " with uncommitted changes to the sources (the commit that records this file)"
out = ["# Speed against libviso2: median time per frame (ms), one pinned core", "",
       f"Machine: {model}. vobench {commit} (Release, `vobench run --dataset`, `vo_ms_median`); "
       f"libviso2 (srv/viso2, VisualOdometryStereo with its default parameters, -O3 -msse3; the "
       f"process() call of each frame but the first). {datetime.date.today().isoformat()}, "
       f"`results/speed/viso2/measure.sh`: all frames of the rendered L-hallway, {repeats} runs "
       f"each, alternating; the median of the runs' medians.", ""]
hdr = ("| frames | vobench | libviso2 | ratio | vobench's frames | libviso2's frames |" +
       (" previous main | ratio to it |" if base else ""))
out += [hdr, "|" + "---|" * (hdr.count("|") - 1)]
csv = ["size,vobench_ms,libviso2_ms,ratio" + (",base_ms" if base else "")]
for size, res in (("hallway", "320x240"), ("kitti", "1241x376")):
    n, v = vobench("new", size), viso2(size)
    row = f"| {res} | **{n:.2f}** | {v:.2f} | **{n / v:.2f}** | {accuracy(size)}"
    line = f"{res},{n:.4f},{v:.4f},{n / v:.4f}"
    if base:
        b = vobench("base", size)
        row += f" {b:.2f} | {n / b:.2f} |"
        line += f",{b:.4f}"
    out.append(row); csv.append(line)
here = os.path.join(os.getcwd(), "results", "speed")
open(f"{here}/viso2.md", "w").write("\n".join(out) + "\n")
open(f"{here}/viso2.csv", "w").write("\n".join(csv) + "\n")
print("\n".join(out))
PY
