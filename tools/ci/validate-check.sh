#!/usr/bin/env bash
# CI, reduced (docs/validate.md): `bdptref validate` on the whole conformance suite with bdptref's own
# estimators as the port (each must pass), then a few port bugs of tools/port_bugs.py through
# tools/validate_classifier.py (each must be flagged). Fixed --spp instead of a time budget, so the
# verdicts do not depend on the machine's load: a run that passes once passes every time.
#   tools/ci/validate-check.sh BUILD_DIR      (a configured Release build; bdptref is (re)built)
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:?usage: tools/ci/validate-check.sh BUILD_DIR}
cmake --build "$build" --target bdptref
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# The samples per render are half those of 4.0, which compared 4 renders: validate now compares 8
# (docs/validate.md, "Budget and samples"), so each scene gets the same samples in all.
# depth-limit-caustic is all light-traced caustic: a verdict needs about 40 spp x 8 (a budget gives it
# that by itself), so at these fixed counts it runs apart, with 64.
scenes=$(/usr/bin/python3 -c 'import json, sys; print(",".join(s["name"] for s in json.load(open(sys.argv[1]))["scenes"] if s["name"] != "depth-limit-caustic"))' scenes/conformance/suite.json)
# glossy-point-light's light tracing (camera connections off a glossy ball, heavy-tailed) needs about
# 35 spp x 8 for a verdict, so the light tracer runs it apart too, with 64.
for port in "path 48" "lt 32" "bdpt 12" "wavefront 8"; do
    set -- $port
    these=$scenes
    [ "$1" = lt ] && these=$(echo "$scenes" | sed 's/,glossy-point-light//; s/^glossy-point-light,//')
    echo "validate-check: bdptref validate --self $1 --spp $2 (every scene but depth-limit-caustic$([ "$1" = lt ] && echo ' and glossy-point-light'))"
    "$build/bdptref" validate --self "$1" --spp "$2" --scenes "$these" --drop-renders -q -o "$out/$1"
done
echo "validate-check: bdptref validate --self lt --spp 64 --scenes glossy-point-light"
"$build/bdptref" validate --self lt --spp 64 --scenes glossy-point-light --drop-renders -q -o "$out/lt-glossy"
for port in lt bdpt wavefront; do
    echo "validate-check: bdptref validate --self $port --spp 64 --scenes depth-limit-caustic"
    "$build/bdptref" validate --self "$port" --spp 64 --scenes depth-limit-caustic --drop-renders -q -o "$out/$port-depth-limit"
done
/usr/bin/python3 tools/validate_classifier.py --in-place "$build" --spp 16 --work "$out/classifier" \
    --bugs lambert-missing-inv-pi,nee-missing-light-cosine,camera-importance-cos3,subpath-roulette-not-divided
echo "validate-check: passed"
