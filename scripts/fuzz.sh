#!/usr/bin/env bash
# Fuzzing: builds the libFuzzer targets of tests/fuzz with clang (address and undefined-
# behaviour sanitizers on) in ./build-fuzz and runs each for SECONDS (default 60), starting
# from the committed corpus in tests/fuzz/corpus (the HDF5 images and the forcing files'
# seeds are made here). A crash, a hang (10 s per input), 2 GB of memory, a failed check or a
# sanitizer report fails the script; libFuzzer leaves the input as build-fuzz/crash-* (oom-*,
# timeout-*).
#   scripts/fuzz.sh [SECONDS]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
bash "$root/scripts/setup.sh"
build="${FLOEDEM_FUZZ_BUILD_DIR:-$root/build-fuzz}"
jobs="$(nproc 2>/dev/null || echo 2)"
# -g1 (line tables): enough for file:line in a crash's stack trace, and a faster build than -g.
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DFLOEDEM_FUZZ=ON -DBUILD_TESTING=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target fuzz_scenario fuzz_contact fuzz_h5 fuzz_inputs make_input_seeds
cd "$build"
# The HDF5 seeds are stored gzipped (tests/fuzz/make_h5_corpus.sh): unpacked here.
rm -rf "$build/seed-h5"
mkdir -p "$build/seed-h5"
for f in "$root"/tests/fuzz/corpus/h5/*.h5.gz; do gunzip -c "$f" > "$build/seed-h5/$(basename "$f" .gz)"; done
# The forcing files' and charts' seeds are written by netCDF-C and as text (make_input_seeds.cpp).
rm -rf "$build/seed-inputs"
"$build/make_input_seeds" "$build/seed-inputs"
for target in scenario contact h5 inputs; do
  work="$build/corpus-$target"  # new inputs go here; the committed corpus is read only
  seeds="$root/tests/fuzz/corpus/$target"
  extra=()
  if [[ $target == h5 ]]; then
    # Its mutator edits images through HDF5, or mutates the datasets' stored bytes, half and
    # half (fuzz_h5.cpp); a cross-over of two images is nearly always no HDF5 file at all.
    seeds="$build/seed-h5"
    extra=(-cross_over=0 -max_len=2000000)
  elif [[ $target == inputs ]]; then
    seeds="$build/seed-inputs"
    extra=(-max_len=65536)
  fi
  mkdir -p "$work"
  echo "fuzz: $target for $seconds s"
  status=0
  "$build/fuzz_$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "${extra[@]}" \
    "$work" "$seeds" > "$build/fuzz_$target.log" 2>&1 || status=$?
  grep -E "stat::number_of_executed_units|ERROR|SUMMARY|Test unit written" "$build/fuzz_$target.log" || true
  if [[ $status -ne 0 ]]; then
    echo "fuzz: $target failed (exit $status); log in $build/fuzz_$target.log:" >&2
    tail -n 60 "$build/fuzz_$target.log" >&2
    exit 1
  fi
done
