#!/usr/bin/env bash
# Robustness sweep of issue #9, the figures in results/robustness/summary.md: l_hallway with
# texture seeds 1-10 (only textures.seed changed) x frame strides 1, 2, 3, 5 (and 8 on seed 7)
# x eleven VO configurations, plus camera.pitch_deg 10, a 640x480 camera (same field of view) and
# the low-texture plain_corridor scene at strides 1, 2, 3, 5.
# Each hallway is rendered once (vobench render, KITTI layout) and every run reads the same
# frames (vobench run --dataset --stride), which gives the same trajectories as simulating each
# run anew (suites/robustness.yaml) with imu.gyro_prior: false, at a tenth of the time: the
# KITTI layout carries no IMU, so these are the VO without the gyro (on by default for a
# sequence with one; the same 40 default runs with it: results/gyro_prior/vehicle_sweep.md).
#   results/robustness/sweep.sh [WORK_DIR]      # default /tmp/vobench_robustness; ~40 min at -j2
#   CONFIGS="default paper" results/robustness/sweep.sh   # a subset of the configurations
#   BIN=/path/to/vobench JOBS=1 results/robustness/sweep.sh   # another build, one job
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
BIN="${BIN:-$ROOT/build/vobench}"  # BIN=... another build
WORK="${1:-/tmp/vobench_robustness}"
JOBS="${JOBS:-2}"
mkdir -p "$WORK"
[ -x "$BIN" ] || { echo "sweep: build first (./setup.sh)"; exit 1; }

# Scenario variants of scenes/l_hallway.yaml (scene path made absolute).
variant() {  # name sed-expression
  sed -e "s|^name: l_hallway|name: $1|" -e "s|^scene: hallway_l.xml|scene: $ROOT/scenes/hallway_l.xml|" \
      -e "$2" scenes/l_hallway.yaml > "$WORK/$1.yaml"
}
datasets=()
for s in 1 2 3 4 5 6 7 8 9 10; do variant "seed$s" "s|^  seed: 7 |  seed: $s |"; datasets+=("seed$s"); done
variant pitch10 "s|^  pitch_deg: 0 |  pitch_deg: 10 |"; datasets+=(pitch10)
variant vga "s|^  width: 320|  width: 640|;s|^  height: 240|  height: 480|"; datasets+=(vga)
sed -e "s|^scene: corridor_plain.xml|scene: $ROOT/scenes/corridor_plain.xml|" scenes/plain_corridor.yaml \
  > "$WORK/corridor.yaml"; datasets+=(corridor)  # the low-texture corridor, a scene of its own
printf '%s\n' "${datasets[@]}" | xargs -P "$JOBS" -I{} bash -c \
  '[ -d "'"$WORK"'/ds_{}" ] || "'"$BIN"'" render "'"$WORK"'/{}.yaml" --out "'"$WORK"'/ds_{}" -q > /dev/null'
# `render` writes the camera's mounting (rig.yaml): `vobench run --dataset` then knows the rig's
# axle, so `platform: auto` (the default) runs the simulated robot as a ground vehicle with that
# axle, as `vobench run l_hallway` does. The `platform: free` configurations below read the same
# frames without rig.yaml (ds_<name>_norig, links to the files): they give the axle themselves
# (the `_rig` ones 0.15 m, the others 0, as their rows were measured).
for d in "${datasets[@]}"; do
  v="$WORK/ds_${d}_norig"
  [ -d "$v" ] && continue
  mkdir "$v"
  for f in "$WORK/ds_$d"/*; do [ "$(basename "$f")" = rig.yaml ] || ln -s "$f" "$v/"; done
done

# VO configurations (partial VO YAMLs over the defaults; keys grouped by the pipeline's stages).
# cfg NAME KEY=VALUE...: writes $WORK/NAME.yaml, one nested YAML map from the dotted keys.
cfg() {
  local name=$1; shift
  /usr/bin/python3 -c 'import sys
tree = {}
for kv in sys.argv[2:]:
    key, value = kv.split("=", 1)
    node = tree
    *path, leaf = key.split(".")
    for p in path: node = node.setdefault(p, {})
    node[leaf] = value
def dump(node, indent):
    for k, v in node.items():
        if isinstance(v, dict): print(" " * indent + k + ":"); dump(v, indent + 2)
        else: print(" " * indent + k + ": " + v)
sys.stdout = open(sys.argv[1], "w"); dump(tree, 0)' "$WORK/$name.yaml" "$@"
}
M=tracker.matcher.type
cfg default $M=svd_ncc_gabor
cfg free platform=free $M=svd_ncc_gabor
cfg paper platform=free $M=svd_ncc_gabor tracker.matcher.prediction=none recovery.reinit_after_lost_frames=1
cfg lucas_kanade $M=lucas_kanade
cfg ncc_mutual $M=ncc_mutual
# The ground vehicle's options one by one on the free platform (README, "Robust tracking"):
# few-point motion, alone and with the ground-vehicle (planar) constraint; the last one is what
# platform ground_vehicle switches on.
cfg few_point platform=free $M=svd_ncc_gabor motion.few_point.enabled=true
cfg few_point_ground platform=free $M=svd_ncc_gabor motion.few_point.enabled=true vehicle.enabled=true
cfg ground platform=free $M=svd_ncc_gabor vehicle.enabled=true
# Both, with the rig's calibration: the camera 0.15 m ahead of the wheel axle (camera.forward_m, set in
# scenes/l_hallway.yaml, the default for plain_corridor; given here as on the free platform).
RIG="platform=free $M=svd_ncc_gabor motion.few_point.enabled=true vehicle.enabled=true vehicle.axle_behind_camera_m=0.15"
cfg few_point_ground_rig $RIG
# The same with the planar motion prior in the window's bundle adjustment (it needs the axle).
cfg few_point_ground_rig_planar $RIG back_end.vehicle_planar.enabled=true
# And with the flat floor (every pose held to the first pose's floor tilt and camera height).
cfg few_point_ground_rig_planar_floor $RIG back_end.vehicle_planar.enabled=true back_end.flat_floor.enabled=true
runs=()
for c in ${CONFIGS:-default free paper lucas_kanade ncc_mutual few_point few_point_ground ground few_point_ground_rig few_point_ground_rig_planar few_point_ground_rig_planar_floor}; do
  for s in 1 2 3 4 5 6 7 8 9 10; do for k in 1 2 3 5; do runs+=("seed$s $k $c"); done; done
  runs+=("seed7 8 $c" "pitch10 1 $c" "vga 1 $c")
  for k in 1 2 3 5; do runs+=("corridor $k $c"); done
done
printf '%s\n' "${runs[@]}" | xargs -P "$JOBS" -L1 bash -c \
  'out="'"$WORK"'/runs/$0_s$1_$2"; ds="'"$WORK"'/ds_$0"; grep -q "^platform: free" "'"$WORK"'/$2.yaml" && ds="${ds}_norig"
   [ -f "$out/metrics.json" ] || "'"$BIN"'" run --dataset "$ds" --stride $1 --config "'"$WORK"'/$2.yaml" --out "$out" --no-plots -q > /dev/null'
/usr/bin/python3 results/robustness/summarize.py "$WORK/runs" results/robustness
