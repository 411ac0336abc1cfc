#!/bin/sh
# Validate Blender Cycles against bdptref's conformance suite (examples/ports/cycles/README.md).
#
#   examples/ports/cycles/validate.sh [--materials same-model|stock] [--cycles-workarounds]
#                                     [--threads N] [--driver-args '...'] [bdptref validate options]
#
# --materials same-model (default): bdptref's Lambert model in Cycles, on the scenes where both
#   renderers implement the same model (sphere-point-light, cornell-box, white-box, sun-courtyard) unless
#   --scenes is given.
# --materials stock: the glTF importer's own materials and lights, as a user would get them, on
#   every scene a path tracer can render (expect inconsistent scenes: README.md says why).
# --cycles-workarounds: avoid the two Cycles 3.x biases the witnesses show (README.md).
# --threads N: Cycles' threads per render (default: all cores).
# --driver-args '...': more options for cycles_render.py (e.g. '--scale 1.01', a wrong port).
# Everything else goes to `bdptref validate` (--budget, --spp, --renders, --out, --scenes, ...).
#
# Installs nothing. Environment: BLENDER (default: blender on PATH), BDPTREF (default: build/bdptref
# of this repository, else bdptref on PATH).
set -eu

HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
DRIVER="$HERE/cycles_render.py"

materials=same-model
driver_extra=""
scenes_given=0
for arg in "$@"; do
    case "$arg" in --scenes|--scenes=*) scenes_given=1 ;; esac
done
pass=""
while [ $# -gt 0 ]; do
    case "$1" in
        --materials) materials=${2:?--materials needs same-model or stock}; shift 2 ;;
        --materials=*) materials=${1#--materials=}; shift ;;
        --cycles-workarounds) driver_extra="$driver_extra --cycles-workarounds"; shift ;;
        --threads) driver_extra="$driver_extra --threads ${2:?--threads needs a number}"; shift 2 ;;
        --driver-args) driver_extra="$driver_extra ${2?}"; shift 2 ;;
        -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) pass="$pass '$(printf '%s' "$1" | sed "s/'/'\\\\''/g")'"; shift ;;
    esac
done
case "$materials" in
    same-model|stock) ;;
    *) echo "validate.sh: --materials must be same-model or stock (got '$materials')" >&2; exit 2 ;;
esac

BLENDER=${BLENDER:-blender}
if ! command -v "$BLENDER" >/dev/null 2>&1; then
    echo "validate.sh: '$BLENDER' not found. Install Blender (Debian 12: apt-get install blender," >&2
    echo "Blender 3.4.1) or set BLENDER=/path/to/blender. This script installs nothing." >&2
    exit 2
fi
if [ -z "${BDPTREF:-}" ]; then
    if [ -x "$ROOT/build/bdptref" ]; then BDPTREF="$ROOT/build/bdptref"
    elif command -v bdptref >/dev/null 2>&1; then BDPTREF=bdptref
    else
        echo "validate.sh: bdptref not found: build it (README.md) or set BDPTREF=/path/to/bdptref" >&2
        exit 2
    fi
fi

# One Blender process per render, or (when validate has the {seeds} placeholder) one per scene
# for all of its renders, so that Blender's start-up (2-6 s) is paid once per scene.
common="--scene {scene} --spp {spp} --size {width}x{height} --max-depth {max_depth} --env={env} --env-map={env_map} --env-scale={env_scale} --materials $materials$driver_extra"
if "$BDPTREF" validate --help 2>/dev/null | grep -q '{seeds}'; then
    renders="--seeds {seeds} --out {out}"
else
    renders="--seed {seed} --out {out}"
fi
renderer="'$BLENDER' -b --factory-startup --python-exit-code 1 -P '$DRIVER' -- $renders $common"

scenes=""
if [ "$materials" = same-model ] && [ $scenes_given = 0 ]; then
    # Where both renderers implement the same model (README.md, "Scenes"): Lambert materials with
    # constant colours, one-sided emitters, a point light. The others use GGX conductors, glass
    # (Cycles has no eta^2 radiance scaling), volumes, spot lights (another falloff), textures and
    # normal maps the same-model driver does not translate.
    scenes="--scenes sphere-point-light,cornell-box,white-box,sun-courtyard"
fi

eval "set -- $pass"
exec "$BDPTREF" validate --suite "$ROOT/scenes/conformance/suite.json" --estimator path \
    --renderer "$renderer" $scenes "$@"
