#!/usr/bin/env bash
# clang-format gate: every tracked *.h/*.cc is formatted as .clang-format says, with the pinned
# clang-format major version (another version formats some constructs differently, so the gate
# would flip-flop between machines). Debian 12: `apt-get install clang-format-14`.
#   tests/format_check.sh            check; exit 1 listing the files that differ
# Env: CLANG_FORMAT (the binary; default clang-format-14, else clang-format if that is 14).
# To reformat (one commit, recorded in .git-blame-ignore-revs):
#   git ls-files '*.h' '*.cc' | xargs clang-format-14 -i
set -euo pipefail
cd "$(dirname "$0")/.."
readonly kMajor=14

bin="${CLANG_FORMAT:-}"
if [ -z "$bin" ]; then
  for b in "clang-format-$kMajor" clang-format; do
    command -v "$b" > /dev/null && { bin="$b"; break; }
  done
fi
if [ -z "$bin" ] || ! command -v "$bin" > /dev/null; then
  echo "format check: clang-format $kMajor not found (Debian 12: apt-get install clang-format-$kMajor)" >&2
  exit 2
fi
version="$("$bin" --version | head -n 1)"
full="$(sed -nE 's/.*clang-format version ([0-9][0-9.]*).*/\1/p' <<< "$version")"
major="${full%%.*}"
if [ "$major" != "$kMajor" ]; then
  echo "format check: $bin is version ${major:-unknown} (\"$version\"); this gate is pinned to" \
       "clang-format $kMajor (Debian 12: apt-get install clang-format-$kMajor, or set CLANG_FORMAT)" >&2
  exit 2
fi

if git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.h' '*.cc')
else
  mapfile -t files < <(find . -path ./build\* -prune -o -type f \( -name '*.h' -o -name '*.cc' \) -print | sed 's|^\./||' | sort)
fi
differ=0
replacements=0
for f in "${files[@]}"; do
  [ -f "$f" ] || continue  # deleted in the work tree, not yet committed
  out="$("$bin" --style=file --dry-run --Werror "$f" 2>&1)" && continue
  n="$(grep -c 'error: code should be clang-formatted' <<< "$out" || true)"
  echo "$f: $n replacement(s)"
  differ=$((differ + 1))
  replacements=$((replacements + n))
done
if ((differ)); then
  echo "format check: $differ of ${#files[@]} files differ from .clang-format ($replacements replacement(s))" \
       "with $bin $full; see a file's changes: $bin --style=file FILE | diff FILE -"
  exit 1
fi
echo "format check: ${#files[@]} files formatted ($bin $full)"
