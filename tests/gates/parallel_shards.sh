#!/usr/bin/env bash
# Runs the README's GNU-parallel shard recipe ("Suites, shards and regression checks") on this
# machine and checks that the merged summary equals the unsharded run's.
# The recipe's commands are taken from README.md (so the test fails when they stop working), with
# local job slots instead of ssh hosts (`nodes` = "2/:", GNU parallel's name for this machine),
# a 4-run suite of 12 frames per run instead of suites/hallway.yaml, a temporary folder instead
# of /srv/vobench, and no rsync (one machine). Compared: summary.csv without its timing columns
# (vo_ms_*, stage_ms_median.*, wall_s: the wall-clock ones) and every run's trajectory.
# Usage: tests/gates/parallel_shards.sh VOBENCH_BINARY
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
readme="$here/../../README.md"
vobench="$(realpath "$1")"
if ! command -v parallel > /dev/null; then
  echo "parallel_shards: GNU parallel not found (Debian: apt-get install parallel; ./setup.sh installs it)" >&2
  exit 1
fi
t="$(mktemp -d)"
trap 'rm -rf "$t"' EXIT
mkdir -p "$t/work"
export PARALLEL_HOME="$t/parallel_home"  # parallel's settings: none of the user's; no citation notice
mkdir -p "$PARALLEL_HOME" && touch "$PARALLEL_HOME/will-cite"

# The recipe: the `parallel ...` command (two lines, joined) and the `... suite merge ...` line.
recipe_parallel="$(sed -n '/^parallel --sshloginfile nodes/{N;s/\\\n//;p;q}' "$readme")"
recipe_merge="$(sed -n '/^build\/vobench suite merge --out out\/suite\/hallway out\/shards\/hallway-{/{p;q}' "$readme")"
if [ -z "$recipe_parallel" ] || [ -z "$recipe_merge" ]; then
  echo "parallel_shards: the GNU parallel recipe (a 'parallel --sshloginfile nodes' command and" \
       "'build/vobench suite merge ...') is not in $readme any more: update this test" >&2
  exit 1
fi
local_cmd() {  # the README's command with this machine's paths
  sed -e "s|/srv/vobench|$t/work|g" -e "s|suites/hallway.yaml|$t/tiny.yaml|g" \
      -e "s|build/vobench|$vobench|g" <<< "$1"
}

cat > "$t/tiny.yaml" <<'YAML'
# 2 scenarios x 1 config x 2 strides = 4 runs, one per shard.
name: tiny
max_frames: 12
scenarios:
  - name: l
    scenario: l_hallway
  - name: corridor
    scenario: plain_corridor
configs:
  - name: paper
strides: [1, 2]
YAML
echo "2/:" > "$t/work/nodes"  # two job slots on this machine

cd "$t/work"
echo "+ $(local_cmd "$recipe_parallel")"
eval "$(local_cmd "$recipe_parallel")" < /dev/null
echo "+ $(local_cmd "$recipe_merge")"
eval "$(local_cmd "$recipe_merge")"
echo "+ $vobench suite $t/tiny.yaml -q -j 2 --out out/unsharded"
"$vobench" suite "$t/tiny.yaml" -q -j 2 --out out/unsharded

# summary.csv without the timing columns (by name), rows in file order.
deterministic() {
  /usr/bin/python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
keep = [i for i, c in enumerate(rows[0]) if not (c.startswith(("vo_ms_", "stage_ms_")) or c == "wall_s")]
for r in rows:
    print(",".join(r[i] for i in keep))
PY
}
status=0
deterministic out/suite/hallway/summary.csv > merged.csv
deterministic out/unsharded/summary.csv > unsharded.csv
if [ "$(wc -l < unsharded.csv)" -ne 5 ]; then
  echo "FAIL: the unsharded summary has $(($(wc -l < unsharded.csv) - 1)) runs, expected 4"; cat unsharded.csv; status=1
fi
if ! diff -u unsharded.csv merged.csv; then
  echo "FAIL: merged summary.csv (above, +) differs from the unsharded one (-) beyond timing columns"; status=1
fi
for run in out/unsharded/runs/*/; do
  id="$(basename "$run")"
  cmp "$run/trajectory_world_tum.txt" "out/suite/hallway/runs/$id/trajectory_world_tum.txt" ||
    { echo "FAIL: run $id: the merged trajectory differs"; status=1; }
done
((status == 0)) && echo "parallel_shards: merged summary of 4 shards == unsharded summary ($(($(wc -l < merged.csv) - 1)) runs)"
exit $status
