#!/usr/bin/env bash
# CI: runs both recipes of docs/distributed.md for real and checks that each merged EXR equals the
# single render of the same settings.
#
#   bash tools/ci/distributed-check.sh BUILD_DIR      (as root, on Debian 12; BUILD_DIR holds
#                                                      bdptref and bdptref_tests)
#
# - GNU parallel: tools/distributed/render-parallel.sh, with the Debian `parallel` package.
# - Slurm: a private one-node cluster of this machine (Debian slurmctld + slurmd + munge; its own
#   slurm.conf, munge key and socket, state and logs in a temporary folder, ports 16817/16818, so
#   nothing in /etc is used or changed), then tools/distributed/slurm-submit.sh with no SBATCH_OPTS:
#   the recipe must run on a node of whatever size this machine is.
# Each merged EXR must hold the same samples with bit-identical counts and every double sum within
# the summation-order bound of docs/ground-truth.md (checked by the hidden test case
# "[.distributed-check]" of bdptref_tests, which reads the exact state with the project's own
# reader, so the check follows the EXR layout wherever docs/exr.md puts it), and
# `bdptref compare` must call it consistent with the single render.
#
# Where this machine cannot run the Slurm daemons (not root, no munged/slurmd), the Slurm part
# prints a line "SKIPPED: <reason>" (and "[SKIPPED]") and the script still exits 0: a skip is
# never reported as a pass. The daemons are stopped and the temporary folder removed on any exit.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: bash tools/ci/distributed-check.sh BUILD_DIR}" && pwd)
bin=$build/bdptref
tests=$build/bdptref_tests
scene=$repo/scenes/cornell-box.gltf
# 32x32, 4 parts of 8 samples: seconds on 2 cores, and enough passes (32) to exercise the bound.
settings=(--width 32 --height 32)
tasks=4 chunk=8 spp=32
start=$SECONDS

for f in "$bin" "$tests"; do
  [ -x "$f" ] || { echo "distributed-check: $f is missing (build bdptref and bdptref_tests first)" >&2; exit 2; }
done

say() { echo "distributed-check: $*"; }
skipped=()
skip() {
  echo "SKIPPED: $*"
  echo "[SKIPPED] distributed-check: $*"
  skipped+=("$*")
}

# --- packages: apt-get update once, and only when something is missing ------------------------
need=()
command -v parallel >/dev/null || need+=(parallel)
command -v munged >/dev/null || need+=(munge)
command -v slurmctld >/dev/null || need+=(slurmctld)
command -v slurmd >/dev/null || need+=(slurmd)
command -v sbatch >/dev/null || need+=(slurm-client)
if [ "$(id -u)" -ne 0 ]; then
  # Not root: no installing and no Slurm daemons (that part is skipped below); GNU parallel only.
  command -v parallel >/dev/null || { echo "distributed-check: GNU parallel is missing and this is not root" >&2; exit 2; }
  need=()
fi
if [ ${#need[@]} -gt 0 ]; then
  say "installing ${need[*]}"
  # The packages' maintainer scripts would start munge/slurmd/slurmctld system services with the
  # configuration in /etc; forbid that for the duration of the install (policy-rc.d, exit 101).
  policy=
  if [ ! -e /usr/sbin/policy-rc.d ]; then
    policy=/usr/sbin/policy-rc.d
    printf '#!/bin/sh\nexit 101\n' >"$policy"
    chmod 755 "$policy"
  fi
  export DEBIAN_FRONTEND=noninteractive
  rc=0
  { apt-get -o DPkg::Lock::Timeout=300 -qq update &&
    apt-get -o DPkg::Lock::Timeout=300 -qq install -y --no-install-recommends "${need[@]}" >/dev/null; } || rc=$?
  [ -z "$policy" ] || rm -f "$policy"
  [ $rc -eq 0 ] || { echo "distributed-check: apt-get install ${need[*]} failed ($rc)" >&2; exit 1; }
fi

# --- a private temporary folder, cleaned up on every exit ----------------------------------------
tmp=$(mktemp -d /tmp/bdptref-distributed.XXXXXX)
# munged refuses a socket in a folder that not everyone can enter.
chmod 755 "$tmp"
export SLURM_CONF=$tmp/slurm.conf
cleanup() {
  local rc=$?
  # Jobs first (their slurmstepd ends the renders), then the daemons, by their pid files.
  if [ -f "$tmp/slurmctld.pid" ] && [ -f "$SLURM_CONF" ]; then
    scancel --quiet --user=root 2>/dev/null || true
    for _ in $(seq 50); do [ -z "$(squeue -h 2>/dev/null)" ] && break; sleep 0.1; done
  fi
  for p in slurmd slurmctld munge/munged; do
    if [ -f "$tmp/$p.pid" ]; then
      pid=$(cat "$tmp/$p.pid")
      kill "$pid" 2>/dev/null || true
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -9 "$pid" 2>/dev/null || true
    fi
  done
  rm -rf "$tmp"
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM

fail() {
  echo "distributed-check: FAILED: $*" >&2
  exit 1
}

# Both merged images against the single render: exact state, then the statistical comparison.
check_equal() {
  local name=$1 merged=$2
  [ -f "$merged" ] || fail "$name: $merged was not written"
  BDPTREF_MERGED=$merged BDPTREF_SINGLE=$tmp/single.exr "$tests" "[.distributed-check]" >"$tmp/$name.check" 2>&1 ||
    { cat "$tmp/$name.check" >&2; fail "$name: the merged EXR differs from the single render"; }
  grep -q "All tests passed" "$tmp/$name.check" || { cat "$tmp/$name.check" >&2; fail "$name: the comparison did not run"; }
  "$bin" compare "$merged" "$tmp/single.exr" >"$tmp/$name.compare" 2>&1 ||
    { cat "$tmp/$name.compare" >&2; fail "$name: bdptref compare does not call it consistent"; }
  say "$name: merged EXR equals the single render (counts exact, sums within 2(n-1)u sum|x|; compare: consistent)"
}

say "single render, $spp spp"
"$bin" render "$scene" "${settings[@]}" --spp "$spp" -q --no-preview -o "$tmp/single.exr"

# --- GNU parallel ------------------------------------------------------------------------------
parallel --version 2>/dev/null | grep -q "GNU parallel" || fail "'parallel' is not GNU parallel ($(command -v parallel))"
say "GNU parallel: $((spp / chunk)) parts of $chunk samples, 2 jobs at a time"
BDPTREF=$bin JOBS=2 SSHLOGINS=: PARTS_DIR=$tmp/parallel.parts \
  "$repo/tools/distributed/render-parallel.sh" "$tmp/parallel.exr" "$spp" "$chunk" "$scene" "${settings[@]}"
check_equal "GNU parallel" "$tmp/parallel.exr"

# --- Slurm -------------------------------------------------------------------------------------
slurm_logs() {
  for f in "$tmp"/munge/munged.log "$tmp"/log/*.log "$tmp"/run/*.log "$tmp"/run/*.out; do
    [ -f "$f" ] || continue
    echo "----- $f" >&2
    tail -n 40 "$f" >&2
  done
}
run_slurm() {
  if [ "$(id -u)" -ne 0 ]; then
    skip "Slurm recipe: not root (the check starts munged, slurmctld and slurmd as root)"
    return
  fi
  local host
  host=$(hostname -s)
  mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/log" "$tmp/run"
  # A key of our own: this cluster authenticates with nothing of the machine's.
  head -c 1024 /dev/urandom >"$tmp/munge/munge.key"
  chmod 400 "$tmp/munge/munge.key"
  if ! munged --socket="$tmp/munge/munge.socket" --key-file="$tmp/munge/munge.key" \
    --pid-file="$tmp/munge/munged.pid" --log-file="$tmp/munge/munged.log" \
    --seed-file="$tmp/munge/munged.seed" ||
    ! munge -n -S "$tmp/munge/munge.socket" | unmunge -S "$tmp/munge/munge.socket" >/dev/null; then
    slurm_logs
    skip "Slurm recipe: munged does not run on this machine (log above)"
    return
  fi
  # One node: this machine's CPUs, a memory figure Slurm does not enforce (CR_CPU: only CPUs are
  # consumable), no cgroups (proctrack/linuxproc, task/none), no accounting. The node is reached
  # at 127.0.0.1 whatever the host name resolves to. kill_invalid_depend: a merge whose array
  # failed is cancelled instead of pending forever.
  cat >"$SLURM_CONF" <<EOF
ClusterName=bdptrefci
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.socket
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerParameters=sched_interval=1
DependencyParameters=kill_invalid_depend
ReturnToService=2
SlurmdParameters=config_overrides
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=1000 State=UNKNOWN
PartitionName=ci Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  if ! slurmctld -f "$SLURM_CONF" || ! slurmd -f "$SLURM_CONF"; then
    slurm_logs
    skip "Slurm recipe: slurmctld or slurmd does not start on this machine (logs above)"
    return
  fi
  local state=
  for _ in $(seq 60); do
    state=$(sinfo -h -N -o %T 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.5
  done
  if [ "$state" != idle ]; then
    slurm_logs
    skip "Slurm recipe: the node of the private cluster never became idle (state '$state', logs above)"
    return
  fi
  say "Slurm: one node of $(nproc) CPUs is idle; submitting $tasks tasks of $chunk samples and the merge"
  # From $tmp/run, so the jobs' logs (written in the submission folder) land there.
  (cd "$tmp/run" && BDPTREF=$bin PARTS_DIR=$tmp/slurm.parts \
    "$repo/tools/distributed/slurm-submit.sh" "$tmp/slurm.exr" "$tasks" "$chunk" "$scene" "${settings[@]}")
  local left=
  for _ in $(seq 240); do
    left=$(squeue -h -o '%i %j %T %r' 2>/dev/null)
    [ -z "$left" ] && break
    # Reasons that never clear by waiting: the request does not fit the node or partition.
    case "$left" in *PartitionConfig* | *PartitionNodeLimit* | *BadConstraints* | *DependencyNeverSatisfied*) break ;; esac
    sleep 0.5
  done
  if [ -n "$left" ]; then
    echo "$left" >&2
    slurm_logs
    fail "Slurm: jobs still queued (above: id, name, state, reason; waited at most 120 s)"
  fi
  [ -f "$tmp/slurm.exr" ] || { slurm_logs; fail "Slurm: the merge job did not write $tmp/slurm.exr"; }
  check_equal "Slurm" "$tmp/slurm.exr"
}
run_slurm

if [ ${#skipped[@]} -gt 0 ]; then
  say "done in $((SECONDS - start)) s, with parts SKIPPED: ${skipped[*]}"
else
  say "both recipes passed in $((SECONDS - start)) s"
fi
