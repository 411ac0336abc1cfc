#!/usr/bin/env bash
# Renders pixel samples [0, SPP) of a scene as parts of CHUNK samples with GNU parallel, on this
# machine or on ssh hosts, then merges them exactly (docs/distributed.md).
#
#   tools/distributed/render-parallel.sh OUT.exr SPP CHUNK SCENE [render options...]
#
# Environment:
#   BDPTREF    the bdptref executable (default: bdptref on PATH); the same path on every host
#   SSHLOGINS  GNU parallel --sshlogin list, e.g. "8/node1,8/node2" ("N/host": N jobs there);
#              default ":" = this machine only, no ssh
#   JOBS       parallel jobs per host when SSHLOGINS does not say (default 1: each render uses
#              every core of its host)
#   PARTS_DIR  where the parts go (default OUT.exr.parts); with ssh hosts it must be on a file
#              system they all share (as must the scene), or see docs/distributed.md
# The parts stay in PARTS_DIR (each is a complete, resumable EXR); the merge refuses parts that
# differ in scene or settings, overlap or leave gaps.
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n '2,18p' "$0" >&2
  exit 2
fi
out=$1 spp=$2 chunk=$3 scene=$4
shift 4
bdptref=${BDPTREF:-bdptref}
parts=${PARTS_DIR:-$out.parts}
mkdir -p "$parts"
parts=$(cd "$parts" && pwd)
case "$scene" in /*) ;; *) scene="$(pwd)/$scene" ;; esac

ranges=()
for ((a = 0; a < spp; a += chunk)); do
  b=$((a + chunk < spp ? a + chunk : spp))
  ranges+=("$a:$b")
done
# One job per sample range; -q quotes the command for the remote shell; a failed job stops the rest.
printf '%s\n' "${ranges[@]}" |
  parallel --will-cite --halt now,fail=1 -j "${JOBS:-1}" --sshlogin "${SSHLOGINS:-:}" -q \
    "$bdptref" render "$scene" "$@" -q --no-preview --sample-range {} -o "$parts/part-{#}.exr"
files=()
for ((k = 1; k <= ${#ranges[@]}; ++k)); do files+=("$parts/part-$k.exr"); done
"$bdptref" merge "${files[@]}" -o "$out"
