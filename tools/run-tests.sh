#!/usr/bin/env bash
# Configures, builds (Release, warnings on) and runs the whole test suite through CTest.
# Usage: tools/run-tests.sh [build-dir] [extra cmake args...]
# CTEST_EXCLUDE (optional): a regex of test names to leave out (for local runs; CI runs everything).
# BDPTREF_KEEP_TEST_FILES=1 (optional): keep the files tests write under the temp dir (removed by
# default when each test process exits), to look at what a failing test wrote.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
shift || true
cmake -S . -B "$build" -G Ninja "$@" >/dev/null
cmake --build "$build"
cd "$build"
# catch_discover_tests silently merges test names that contain ';' or '[': make sure CTest sees
# every Catch2 test case.
# (Catch2 v2 exits with the number of tests it listed, hence the "|| true")
n_catch=$({ ./bdptref_tests --list-test-names-only || true; } | grep -c .)
# Tests labelled "script" (bench_smoke) are CTest-only and not counted.
n_ctest=$(ctest -N -LE script | sed -n 's/^Total Tests: //p')
if [ "$n_catch" != "$n_ctest" ]; then
  echo "run-tests: CTest discovered $n_ctest tests but Catch2 has $n_catch (a test name with ';' or '['?)" >&2
  exit 1
fi
if [ -n "${CTEST_EXCLUDE:-}" ]; then
  echo "run-tests: leaving out tests matching '$CTEST_EXCLUDE'"
  ctest --output-on-failure -j2 --timeout 900 -E "$CTEST_EXCLUDE"
else
  ctest --output-on-failure -j2 --timeout 900
fi
