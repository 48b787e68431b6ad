#!/usr/bin/env bash
# Include-boundary gate: the dependency direction of docs/DESIGN.md ("The house"), checked on the
# #include lines of the modules' own sources (every *.h/*.cc under vo/, sim/, harness/).
#   vo/       includes vo/ only, never MuJoCo or OpenGL (usable without the simulator)
#   sim/      includes sim/ only (never vo/ or harness/)
#   harness/  includes vo/, sim/, harness/
# and no module reaches out with a relative path ("../"). tests/ may include everything.
# Usage: tests/gates/include_boundaries.sh [SOURCE_ROOT]   (default: the checkout of this script)
# Exit 0 when clean; 1 with one line per offending include, "file:line: ...", and a summary.
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/../.." && pwd)}"
cd "$root"

# The project folders a module may include from, and third-party prefixes it must not.
declare -A allowed=([vo]="vo" [sim]="sim" [harness]="vo sim harness")
declare -A forbidden_third_party=([vo]="mujoco/ GL/" [sim]="" [harness]="")
modules=(vo sim harness)

bad=0
checked=0
for m in "${modules[@]}"; do
  [ -d "$m" ] || continue
  while IFS= read -r -d '' f; do
    checked=$((checked + 1))
    # "<line>:<included path>" for every #include of the file.
    while IFS=: read -r line inc; do
      top="${inc%%/*}"
      why=""
      if [[ "$inc" == ../* || "$inc" == */../* ]]; then
        why="relative include out of the folder; name it from the source root (vo/..., sim/...)"
      elif [[ "$inc" == */* ]] && [[ " vo sim harness " == *" $top "* ]] &&
           [[ " ${allowed[$m]} " != *" $top "* ]]; then
        # shellcheck disable=SC2086  # the list is split into its words on purpose
        ok_list="$(printf '%s/, ' ${allowed[$m]})"
        why="$m/ may include only ${ok_list%, } (docs/DESIGN.md: $m/ never depends on $top/)"
      else
        for p in ${forbidden_third_party[$m]}; do
          [[ "$inc" == "$p"* ]] && why="$m/ must build without ${p%/} (docs/DESIGN.md: vo/ never uses MuJoCo or OpenGL)"
        done
      fi
      if [ -n "$why" ]; then
        echo "$f:$line: includes \"$inc\": $why"
        bad=$((bad + 1))
      fi
    done < <(grep -n -E '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"][^">]+[">]' "$f" |
             sed -E 's/^([0-9]+):[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]([^">]+)[">].*/\1:\2/')
  done < <(find "$m" -type f \( -name '*.h' -o -name '*.cc' \) -print0 | sort -z)
done

if ((checked == 0)); then
  echo "include boundaries: no sources under $root/{vo,sim,harness}" >&2
  exit 1
fi
if ((bad)); then
  echo "include boundaries: $bad include(s) against the dependency direction in $checked files"
  exit 1
fi
echo "include boundaries: $checked files of vo/, sim/, harness/ follow the dependency direction"
