#!/usr/bin/env bash
# Submits a Slurm job array of TASKS renders of CHUNK samples each (samples [0, TASKS*CHUNK)) and
# a merge job that runs when all of them succeeded (docs/distributed.md).
#
#   tools/distributed/slurm-submit.sh OUT.exr TASKS CHUNK SCENE [render options...]
#
# Extra sbatch options (partition, time limit, account) go in SBATCH_OPTS, e.g.
# SBATCH_OPTS="--partition=cpu --time=04:00:00". PARTS_DIR defaults to OUT.exr.parts; it must be
# on a file system the compute nodes share. No CPU count is requested: each task gets Slurm's
# default allocation (one CPU or core) and renders with every CPU it was given; for more per task
# add e.g. SBATCH_OPTS="--cpus-per-task=16" or "--exclusive" (whole nodes).
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n '2,11p' "$0" >&2
  exit 2
fi
out=$1 tasks=$2 chunk=$3 scene=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
parts=${PARTS_DIR:-$out.parts}
# Absolute paths: the jobs may start in another folder (SBATCH_OPTS="--chdir=...").
abs() { case "$1" in /*) echo "$1" ;; *) echo "$(pwd)/$1" ;; esac; }
out=$(abs "$out") parts=$(abs "$parts") scene=$(abs "$scene")
# shellcheck disable=SC2086
array=$(sbatch --parsable ${SBATCH_OPTS:-} --array="0-$((tasks - 1))" "$here/slurm-render.sbatch" "$parts" "$chunk" "$scene" "$@")
files=()
for ((k = 0; k < tasks; ++k)); do files+=("$parts/part-$k.exr"); done
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTS:-} --dependency="afterok:$array" --job-name=bdptref-merge \
  --wrap "$(printf '%q ' "${BDPTREF:-bdptref}" merge "${files[@]}" -o "$out")")
echo "submitted render array $array and merge job $merge; the result will be $out"
