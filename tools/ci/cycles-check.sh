#!/usr/bin/env bash
# CI (examples/ports/cycles/README.md): Blender Cycles validated end to end as a foreign port.
#   tools/ci/cycles-check.sh BUILD_DIR      (a configured Release build; bdptref is (re)built)
#
# 1. examples/ports/cycles/validate.sh --cycles-workarounds on the scenes where the witnesses show
#    both renderers right (sphere-point-light, cornell-box, white-box, sun-courtyard): must be
#    consistent (exit 0).
# 2. The same driver with its output scaled by 1.01 (Cycles' film exposure) on cornell-box:
#    must be inconsistent (exit 1).
# Fixed --spp and seeds, so the verdicts do not depend on the machine's load (Cycles' image is a
# function of the seed on the CPU). Installs Blender with apt-get when it is missing: meant for the
# CI machine, not for the fresh Debian root of .ci/run's main build.
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:?usage: tools/ci/cycles-check.sh BUILD_DIR}
cmake --build "$build" --target bdptref
if ! command -v blender >/dev/null 2>&1; then
    echo "cycles-check: installing blender (apt-get)"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends blender >/dev/null
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export BDPTREF="$PWD/$build/bdptref"
[ -x "$BDPTREF" ] || BDPTREF="$build/bdptref"
threads=$(nproc)

echo "cycles-check: Cycles (same-model, workarounds) must be consistent"
examples/ports/cycles/validate.sh --cycles-workarounds --threads "$threads" \
    --scenes sphere-point-light,cornell-box,white-box,sun-courtyard --spp 16 --renders 8 --drop-renders -q -o "$out/ok"

echo "cycles-check: Cycles scaled by 1.01 must be inconsistent"
set +e
examples/ports/cycles/validate.sh --cycles-workarounds --threads "$threads" --driver-args "--scale 1.01" \
    --scenes cornell-box --spp 16 --renders 8 --drop-renders -q -o "$out/scaled"
rc=$?
set -e
if [ $rc -ne 1 ]; then
    echo "cycles-check: FAILED: the 1.01-scaled Cycles was not flagged (validate exit $rc, expected 1)" >&2
    exit 1
fi
echo "cycles-check: passed"
