#!/usr/bin/env bash
# Builds the scene-loader fuzzer with clang (libFuzzer + ASan + UBSan) and runs it for a bounded
# time on a corpus seeded with the shipped scenes and the hostile/feature seeds of fuzz/seeds/
# (written by fuzz/make_hostile_seeds.py). Usage: fuzz/run.sh [seconds] [build-dir]
# Exit status: 0 when no crash was found, non-zero otherwise (the crashing input is left in the
# build dir as crash-*; reproduce with: <build-dir>/fuzz/fuzz_scene_loader crash-...).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
build="${2:-build-fuzz}"
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DBDPTREF_FUZZ=ON -DBDPTREF_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --target fuzz_scene_loader
corpus="$build/corpus"
mkdir -p "$corpus"
cp scenes/*.gltf scenes/*.glb fuzz/seeds/* "$corpus"/
# Halt on the first ASan/UBSan report; 2 GB RSS and 10 s per input bound the absurd-size inputs
# (a loader that allocated what a forged header claims would pass 2 GB and count as a crash).
ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
  "$build/fuzz/fuzz_scene_loader" "$corpus" -max_total_time="$seconds" -rss_limit_mb=2048 -malloc_limit_mb=2048 \
  -timeout=10 -max_len=65536 -dict=fuzz/gltf.dict -artifact_prefix="$build/" -print_final_stats=1
