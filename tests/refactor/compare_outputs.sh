#!/usr/bin/env bash
# Byte-for-byte comparison of every command's outputs between two vobench builds: the check of
# a refactoring that must not change behaviour (issue #12). Runs render, run (simulated and on
# the rendered dataset, with a stride), eval (KITTI, and EuRoC when ../shared/data is there),
# match-eval, a tiny suite, check (on that suite) and a small tune with each build, then diffs
# the two output trees. Timing values (wall clock) differ from run to run and are masked before
# the diff: CSV columns and JSON keys named *_ms, *_s (not time_s), ms_per_pair and the
# Markdown table rows that hold them; PNG plots, logs and the folder markers
# (.vobench.json: time, pid, command line) are not compared.
# VO option keys: a build that groups vo_options.yaml by the pipeline's stages (issue #32) gets
# its configs (--config, a suite's `set:`, a tune's parameters) in that spelling, an earlier
# build in the earlier one; before the diff, the earlier keys in either tree are renamed with
# the table of harness/vo_config.cc (RenamedKeys) and a vo_options.yaml is compared as its
# sorted leaves (also the copy in a report.md), so the two spellings of the same options agree;
# when the two builds spell them differently, the specs' hashes (of text that holds the
# options) are masked and runs of blanks (a table's padding around a key) count as one.
#   tests/refactor/compare_outputs.sh OLD_VOBENCH NEW_VOBENCH [WORK_DIR]
# Exit 0 when the trees agree; otherwise lists the files that differ (and the first lines).
set -euo pipefail
OLD=$(realpath "$1")
NEW=$(realpath "$2")
WORK="${3:-$(mktemp -d /tmp/vobench_compare.XXXXXX)}"
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$WORK"
SHORT="$WORK/short.yaml"  # 1.5 m, the turn in place, 2 m: ~80 frames
sed -e "s|^scene: hallway_l.xml|scene: $ROOT/scenes/hallway_l.xml|" -e 's|^name: l_hallway|name: short|' \
    -e '/^path:/,/^robot:/{/^  - /d}' -e 's|^path:.*|path: [[6.5, 0.0], [8.0, 0.0], [8.0, 2.0]]|' \
    "$ROOT/scenes/l_hallway.yaml" > "$SHORT"
EUROC="$ROOT/../shared/data/euroc_v101_clip"

# Whether a build reads the VO options grouped by stage (BIN).
by_stage() { grep -q "grouped by the pipeline's stages" "$1"; }
SPELLINGS_DIFFER=0
if by_stage "$OLD"; then a=1; else a=0; fi
if by_stage "$NEW"; then b=1; else b=0; fi
[ "$a" = "$b" ] || SPELLINGS_DIFFER=1
export SPELLINGS_DIFFER

# The VO configs of one build, in its spelling (BIN DIR): the earlier flat keys or the stages'.
configs() {
  local bin=$1 d=$2 ncc lk sigma
  if by_stage "$bin"; then
    ncc='tracker:\n  matcher:\n    type: ncc_mutual\n'
    lk='tracker.matcher.type'
    sigma='tracker.matcher.svd.sigma_px'
  else
    ncc='matcher:\n  type: ncc_mutual\n'
    lk='matcher.type'
    sigma='matcher.svd.sigma_px'
  fi
  printf "$ncc" > "$d/ncc_vo.yaml"
  cat > "$d/tiny_suite.yaml" <<EOF
name: tiny
scenarios:
  - name: short
    scenario: $SHORT
    max_frames: 40
configs:
  - name: default
  - name: lk
    set: {$lk: lucas_kanade}
strides: [1, 2]
EOF
  cat > "$d/tiny_tune.yaml" <<EOF
name: tiny_tune
train:
  - name: a
    scenario: $SHORT
    max_frames: 30
validation:
  - name: b
    scenario: $SHORT
    set: {seed: 5}
    max_frames: 30
parameters:
  - {key: $sigma, min: 4, max: 30, log: true}
objective:
  metric: ate_rmse_m
  lost_frame_penalty: 0.05
  aggregate: mean
optimizer:
  algorithm: GN_DIRECT_L
  max_evals: 3
EOF
}

outputs() {  # BIN DIR: every command, outputs under DIR
  local bin=$1 d=$2
  rm -rf "$d"
  mkdir -p "$d"
  configs "$bin" "$d"
  (
    cd "$d"
    "$bin" render "$SHORT" --out ds -q > render.stdout
    "$bin" run "$SHORT" --max-frames 60 --no-plots -q --out run_sim > run_sim.stdout
    "$bin" run --dataset ds --stride 2 --no-plots -q --out run_ds > run_ds.stdout
    "$bin" run --dataset ds --config ncc_vo.yaml --max-frames 40 --no-plots -q --out run_cfg > run_cfg.stdout
    "$bin" eval --dataset ds --format kitti --no-plots -q --out eval_kitti > eval_kitti.stdout
    if [ -d "$EUROC" ]; then
      "$bin" eval --dataset "$EUROC" --format euroc --max-frames 40 --no-plots -q --out eval_euroc \
        > eval_euroc.stdout
    fi
    "$bin" match-eval "$SHORT" --strides 1,3 --max-frames 40 -q --out match_eval > match_eval.stdout
    "$bin" suite "$d/tiny_suite.yaml" -j 2 -q --out suite > suite.stdout
    "$bin" check --suite "$d/tiny_suite.yaml" --baseline "$d/suite_baseline.json" -q --update \
      --out check_update > check_update.stdout 2>&1 || true
    "$bin" check --suite "$d/tiny_suite.yaml" --baseline "$d/suite_baseline.json" -q \
      --out check > check.stdout 2>&1 || echo "exit $?" >> check.stdout
    "$bin" tune "$d/tiny_tune.yaml" --no-plots -q --out tune > tune.stdout
  )
}

if [ -z "${COMPARE_ONLY:-}" ]; then  # COMPARE_ONLY=1: diff the trees of an earlier call again
  outputs "$OLD" "$WORK/old"
  outputs "$NEW" "$WORK/new"
fi

# Masks wall-clock values; prints the normalised text of one file.
normalise() {
  /usr/bin/python3 - "$1" "$ROOT/harness/vo_config.cc" <<'PY'
import csv, io, json, os, re, sys
path = sys.argv[1]
# The earlier VO option keys and their names by stage (harness/vo_config.cc, RenamedKeys; an
# empty new key: the option became a constant).
renamed = dict(re.findall(r'\{"([a-z_0-9.]+)",\s*"([a-z_0-9.]*)",\s*(?:nullptr|"[^"]*")\}',
                          open(sys.argv[2]).read()))
def new_key(old):
    best = max((k for k in renamed if old == k or old.startswith(k + '.')), key=len, default=None)
    return old if best is None else (renamed[best] + old[len(best):] if renamed[best] else '')
import yaml
def sorted_leaves(text):
    def leaves(node, prefix=''):
        for k, v in node.items():
            key = prefix + '.' + k if prefix else k
            if isinstance(v, dict):
                yield from leaves(v, key)
            else:
                yield key, v
    out = sorted((new_key(k), v) for k, v in leaves(yaml.safe_load(text) or {}))
    return '\n'.join(f'{k}: {v!r}' for k, v in out if k)
if re.search(r'(vo_options|_vo|\.vo)\.yaml$', path):
    print(sorted_leaves(open(path).read()))
    sys.exit(0)
differ = os.environ.get('SPELLINGS_DIFFER') == '1'
groups = sorted({k.split('.')[0] for k in renamed}, key=len, reverse=True)
dotted = re.compile(r'(?<![\w.])((?:' + '|'.join(groups) + r')\.[a-z_0-9.]*[a-z_0-9])(?![\w])')
def rename_keys(text):
    return dotted.sub(lambda m: new_key(m.group(1)) or m.group(1), text)
timing = re.compile(r'(_ms$|_ms_|^ms_|_s$|ms_per_pair|^wall|seconds)')
def is_timing(key):
    return key != 'time_s' and bool(timing.search(key))
def scrub(v):
    if isinstance(v, dict):
        return {k: ('<t>' if is_timing(k) or (differ and k == 'spec_hash') else scrub(x))
                for k, x in v.items()}
    if isinstance(v, list):
        return [scrub(x) for x in v]
    return v
text = rename_keys(open(path, encoding='utf-8', errors='replace').read())
if path.endswith('report.md'):  # the effective VO options' copy: as its sorted leaves
    text = re.sub(r'```yaml\n(.*?)```', lambda m: '```yaml\n' + sorted_leaves(m.group(1)) + '\n```',
                  text, flags=re.S)
if differ:
    text = re.sub(r' {2,}', ' ', text)
if path.endswith('.json'):
    try:
        print(json.dumps(scrub(json.loads(text)), indent=1, sort_keys=False))
        sys.exit(0)
    except ValueError:
        pass
if path.endswith('.csv'):
    rows = list(csv.reader(io.StringIO(text)))
    if rows:
        masked = [i for i, k in enumerate(rows[0]) if is_timing(k)]
        for r in rows[1:]:
            for i in masked:
                if i < len(r): r[i] = '<t>'
        w = csv.writer(sys.stdout, lineterminator='\n')
        w.writerows(rows)
        sys.exit(0)
# Markdown tables: the cells of columns whose header names a time (ms, wall, seconds).
lines = text.split('\n')
masked = []
for i, line in enumerate(lines):
    if line.startswith('|') and i + 1 < len(lines) and lines[i + 1].startswith('| ---'):
        masked = [j for j, h in enumerate(line.split('|')) if re.search(r'\bms\b|wall|\(s\)|p95', h)]
    elif line.startswith('| ---'):
        pass
    elif line.startswith('|'):
        cells = line.split('|')
        for j in masked:
            if j < len(cells): cells[j] = '<t>'
        lines[i] = '|'.join(cells)
    else:
        masked = []
text = '\n'.join(lines)
# Markdown, stdout and text: times (a number followed by ms or s) masked, and the per-stage
# timing line of `run`.
text = re.sub(r'VO time/frame.*|render speed.*', '<t>', text)
# Plain-text tables whose last column is a time (header ends with ms/frame, ms/pair).
lines = text.split('\n')
timed = False
for i, line in enumerate(lines):
    if re.search(r'\sms/\w+$', line):
        timed = True
    elif timed and line.strip():
        lines[i] = line.rsplit(None, 1)[0] + ' <t>'
    else:
        timed = False
text = '\n'.join(lines)
text = re.sub(r'[0-9.]+( ?/ ?[0-9.]+)? ?(ms|s)\b', '<t>', text)
print(text.replace(sys.argv[1].split('/new/')[0].split('/old/')[0], '<work>'), end='')
PY
}

status=0
cd "$WORK"
while IFS= read -r f; do
  case "$f" in *.png|*/logs/*|*.log|*/.vobench.json|*.lock) continue ;; esac
  if [ ! -e "new/$f" ]; then echo "only in old: $f"; status=1; continue; fi
  if ! cmp -s "old/$f" "new/$f"; then
    if ! diff -q <(normalise "old/$f" | sed "s|$WORK/old|<d>|g;s|$OLD|<bin>|g") \
                 <(normalise "new/$f" | sed "s|$WORK/new|<d>|g;s|$NEW|<bin>|g") > /dev/null; then
      echo "differs: $f"
      diff <(normalise "old/$f" | sed "s|$WORK/old|<d>|g;s|$OLD|<bin>|g") <(normalise "new/$f" | sed "s|$WORK/new|<d>|g;s|$NEW|<bin>|g") | head -8 || true
      status=1
    fi
  fi
done < <(cd old && find . -type f | sort)
while IFS= read -r f; do
  case "$f" in *.png|*/logs/*|*.log|*/.vobench.json|*.lock) continue ;; esac
  [ -e "old/$f" ] || { echo "only in new: $f"; status=1; }
done < <(cd new && find . -type f | sort)
files=$(cd old && find . -type f ! -name '*.png' | wc -l)
if [ "$status" = 0 ]; then echo "compare_outputs: $files files agree (timings masked) in $WORK"; fi
exit "$status"
