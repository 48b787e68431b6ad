#!/usr/bin/env bash
# Fuzz smoke (CI): every libFuzzer target for a few seconds, seeded with the committed corpus
# (copied to a scratch folder, so tests/fuzz/corpus/ is never changed). Fails on any crash,
# sanitizer report, leak or timeout.
#   tests/fuzz/smoke.sh <build folder configured with -DVOBENCH_FUZZ=ON> [seconds per target]
set -euo pipefail
cd "$(dirname "$0")/../.."
build="${1:?usage: tests/fuzz/smoke.sh BUILD_DIR [SECONDS]}"
seconds="${2:-6}"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
for dir in tests/fuzz/corpus/*/; do
  target="$(basename "$dir")"
  mkdir -p "$scratch/$target"
  cp "$dir"* "$scratch/$target/"
  if ! TMPDIR="$scratch" "$build/tests/fuzz/$target" -max_total_time="$seconds" -timeout=10 \
      -rss_limit_mb=4096 -artifact_prefix="$scratch/" "$scratch/$target" > "$scratch/$target.log" 2>&1; then
    tail -n 60 "$scratch/$target.log"
    mkdir -p out/fuzz-smoke && cp "$scratch"/crash-* "$scratch"/leak-* "$scratch"/timeout-* out/fuzz-smoke/ 2>/dev/null || true
    echo "fuzz smoke: $target FAILED (inputs kept in out/fuzz-smoke/)" >&2
    exit 1
  fi
  echo "fuzz smoke: $target ok: $(grep -E '^#[0-9]+' "$scratch/$target.log" | tail -n 1)"
done
