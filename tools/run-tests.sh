#!/usr/bin/env bash
# Configures, builds (Release, warnings on) and runs the whole test suite through CTest.
# Usage: tools/run-tests.sh [build-dir] [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
shift || true
cmake -S . -B "$build" -G Ninja "$@" >/dev/null
cmake --build "$build"
cd "$build"
ctest --output-on-failure -j2 --timeout 900
