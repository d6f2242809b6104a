#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang in build-fuzz/ and runs each reader's
# fuzzer for SECONDS seconds (default 60), one after another.
#
#   scripts/fuzz.sh [SECONDS] [FORMAT...]      e.g. scripts/fuzz.sh 300 ply off
#   scripts/fuzz.sh --replay                   build, then run every reader's fuzzer once over
#                                              each kept input (seeds, tests/data/bad,
#                                              tests/data/fuzz_regressions); ctest runs this
#
# FUZZ_BUILD_DIR overrides the build directory (default build-fuzz/ in the repository).
#
# Corpora persist in build-fuzz/corpus/FORMAT (seeded from tests/fuzz/seeds, tests/data/bad,
# tests/data/fuzz_regressions and the small meshes in data/), so repeated runs build on each
# other. Crashing inputs land in build-fuzz/artifacts/FORMAT/; the script exits non-zero if any
# fuzzer found one. A crash to keep goes to tests/data/bad/ (input that must be rejected) or
# tests/data/fuzz_regressions/ (input that must be read), where the unit tests pick it up.
set -euo pipefail

replay=0
if [ "${1:-}" = "--replay" ]; then replay=1; shift; fi
seconds=${1:-60}
shift || true
formats=("$@")
if [ ${#formats[@]} -eq 0 ]; then formats=(obj ply off stl); fi

root=$(cd "$(dirname "$0")/.." && pwd)
build="${FUZZ_BUILD_DIR:-$root/build-fuzz}"
CC=${CC:-clang}
CXX=${CXX:-clang++}

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER="$CC" -DCMAKE_CXX_COMPILER="$CXX" \
  -DVERTEXFLOW_BUILD_FUZZERS=ON -DVERTEXFLOW_BUILD_TESTS=OFF -DVERTEXFLOW_BUILD_BENCHMARKS=OFF >/dev/null
targets=()
for f in "${formats[@]}"; do targets+=("fuzz_read_$f"); done
cmake --build "$build" --target "${targets[@]}"

# Seeds: every file of the format (plain or .gz) up to 64 kB from the seed directories.
seed() {
  local format=$1 corpus=$2 file
  for dir in "$root/tests/fuzz/seeds" "$root/tests/data/bad" "$root/tests/data/fuzz_regressions" "$root/data"; do
    [ -d "$dir" ] || continue
    for file in "$dir"/*."$format" "$dir"/*."$format".gz; do
      [ -f "$file" ] || continue
      [ "$(stat -c %s "$file")" -le 65536 ] || continue
      cp -f "$file" "$corpus/seed-$(basename "$dir")-$(basename "$file")"
    done
  done
}

if [ "$replay" -eq 1 ]; then
  # Every kept input of the format, plain or gzip, run once (file arguments: no fuzzing). A
  # crash, a sanitizer report or a leak exits non-zero.
  status=0
  for f in "${formats[@]}"; do
    inputs=()
    for dir in "$root/tests/fuzz/seeds" "$root/tests/data/bad" "$root/tests/data/fuzz_regressions"; do
      for file in "$dir"/*."$f" "$dir"/*."$f".gz; do
        [ -f "$file" ] && inputs+=("$file")
      done
    done
    echo "== fuzz_read_$f: replaying ${#inputs[@]} inputs"
    if ! "$build/bin/fuzz_read_$f" -rss_limit_mb=2048 -malloc_limit_mb=512 -timeout=10 "${inputs[@]}" \
      >"$build/replay_$f.log" 2>&1; then
      grep -E '==[0-9]+==ERROR|SUMMARY|runtime error|Running: ' "$build/replay_$f.log" | tail -20 >&2
      echo "!! fuzz_read_$f failed on a kept input; see $build/replay_$f.log" >&2
      status=1
    fi
  done
  exit $status
fi

status=0
for f in "${formats[@]}"; do
  corpus="$build/corpus/$f"
  artifacts="$build/artifacts/$f"
  mkdir -p "$corpus" "$artifacts"
  seed "$f" "$corpus"
  before=$(ls "$artifacts" | wc -l)
  echo "== fuzz_read_$f for ${seconds}s (corpus $corpus)"
  # -timeout: an input taking over 10 s is a hang. -malloc_limit_mb / -rss_limit_mb: the
  # reader's allocations must stay bounded by the input size (at most 64 kB, or 16 MB inflated;
  # see fuzz_read.h), so one 512 MB allocation or 2 GB in all means a header count was trusted.
  rc=0
  "$build/bin/fuzz_read_$f" "$corpus" -dict="$root/tests/fuzz/$f.dict" \
    -artifact_prefix="$artifacts/" -max_total_time="$seconds" -max_len=65536 \
    -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512 -print_final_stats=1 >"$build/fuzz_read_$f.log" 2>&1 || rc=$?
  grep -E '^(#[0-9]+ +(INITED|DONE)|==[0-9]+==ERROR|SUMMARY|stat::(number_of_executed_units|average_exec_per_sec|peak_rss_mb)|Test unit written)' \
    "$build/fuzz_read_$f.log" || true
  if [ "$rc" -ne 0 ] || [ "$(ls "$artifacts" | wc -l)" -ne "$before" ]; then
    echo "!! fuzz_read_$f found a problem (exit $rc); see $build/fuzz_read_$f.log and $artifacts" >&2
    status=1
  fi
done
exit $status
