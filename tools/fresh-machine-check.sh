#!/usr/bin/env bash
# Fresh-machine check: proves that the README's commands work on a just-made Debian 12.
#
# A developer's or CI's machine has packages a new one lacks, so a green build there can hide a
# missing install step (it did: openimageio-tools). This script makes a minimal Debian 12 root with
# `debootstrap --variant=minbase bookworm`, puts a clean clone of this repository's HEAD in it at
# /src, and runs the README's FIRST command verbatim inside `chroot` (read from README.md: the first
# line of its first ```sh block, never retyped here), then checks that the EXR and PNG it promises
# exist and are real files of their formats.
#
# With --tests it then runs the README's SECOND command (the whole test suite) verbatim in the same
# root, so both commands are proven on the fresh system; each --then CMD runs afterwards in /src of
# the same root (.ci/run uses this for the distributed recipes and the installed-library examples,
# so they too are proven on a fresh system).
#
# Usage (as root): tools/fresh-machine-check.sh [--tests] [--then 'CMD']...
# Environment:
#   FRESH_MIRROR   Debian mirror for debootstrap (default: debootstrap's own default)
#   FRESH_WORK     directory to build the root in (default: a new one under /var/tmp; removed after)
#   FRESH_KEEP=1   keep the root afterwards (for debugging)
# Nothing the README installs is cached: every run installs from the mirror, as a new user would.
set -euo pipefail

run_tests=0
then_cmds=()
while [ $# -gt 0 ]; do
  case "$1" in
    --tests) run_tests=1 ;;
    --then) [ $# -ge 2 ] || { echo "fresh-machine-check: --then needs a command" >&2; exit 2; }
            then_cmds+=("$2"); shift ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) echo "fresh-machine-check: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

repo=$(cd "$(dirname "$0")/.." && pwd)
if [ "$(id -u)" -ne 0 ]; then
  echo "fresh-machine-check: must run as root (debootstrap and chroot need it)" >&2
  exit 2
fi

t_start=$(date +%s)
step() { echo "fresh-machine-check: [$(( $(date +%s) - t_start )) s] $*"; }

# The README's commands, verbatim: line 1 of the first and of the second ```sh block.
readme_command() {  # $1 = block number (1 or 2)
  awk -v want="$1" '/^```sh[[:space:]]*$/ { n++; inblock = 1; next }
                    /^```/ { inblock = 0; next }
                    inblock && n == want && NF { print; exit }' "$repo/README.md"
}
first_cmd=$(readme_command 1)
second_cmd=$(readme_command 2)
if [ -z "$first_cmd" ] || [ -z "$second_cmd" ]; then
  echo "fresh-machine-check: README.md must start with two \`\`\`sh blocks (set-up + render, tests)" >&2
  exit 1
fi

if ! command -v debootstrap >/dev/null 2>&1; then
  step "installing debootstrap"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap >/dev/null
fi

work=${FRESH_WORK:-$(mktemp -d /var/tmp/bdptref-fresh.XXXXXX)}
root="$work/root"
mkdir -p "$work"

# Unmount everything under the root (deepest first) before deleting it: deleting through a live
# mount would delete the host's files.
unmount_all() {
  local m
  for m in $(awk -v r="$root" '$2 == r || index($2, r "/") == 1 { print $2 }' /proc/mounts | sort -r); do
    umount "$m" 2>/dev/null || umount -l "$m" 2>/dev/null || true
  done
}
cleanup() {
  local rc=$?
  unmount_all
  if awk -v r="$root" '$2 == r || index($2, r "/") == 1 { found = 1 } END { exit !found }' /proc/mounts; then
    echo "fresh-machine-check: something is still mounted under $root; NOT removing $work" >&2
  elif [ "${FRESH_KEEP:-0}" = 1 ]; then
    echo "fresh-machine-check: kept $work"
  else
    rm -rf "$work"
  fi
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM

step "debootstrap --variant=minbase bookworm $root"
# shellcheck disable=SC2086
if ! debootstrap --variant=minbase bookworm "$root" ${FRESH_MIRROR:-} > "$work/debootstrap.log" 2>&1; then
  tail -n 30 "$work/debootstrap.log" >&2
  echo "fresh-machine-check: debootstrap failed (is the Debian mirror reachable?)" >&2
  exit 1
fi
cp /etc/resolv.conf "$root/etc/resolv.conf"
# A real machine has /proc and /sys mounted (the Slurm daemons of tools/ci/distributed-check.sh
# need sysfs for the CPU topology and the cgroup hierarchy). /sys is bound recursively as a slave,
# so nothing unmounted inside the root propagates back to this machine.
mount -t proc proc "$root/proc"
mount --rbind /sys "$root/sys"
mount --make-rslave "$root/sys"

step "cloning $(git -C "$repo" rev-parse --short HEAD) into the new root's /src"
git clone --quiet --no-hardlinks "$repo" "$root/src"

in_root() {  # runs a command line in the new root with a clean environment, as a new user's shell
  chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 TERM=dumb \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    /bin/bash -c "cd /src && $1"
}

step "README command 1: $first_cmd"
in_root "$first_cmd"

# The first command promises cornell-box.exr and its preview cornell-box.png in /src.
check_magic() {  # $1 file, $2 expected leading bytes as hex
  local f="$root/src/$1" got
  [ -f "$f" ] || { echo "fresh-machine-check: $1 was not written" >&2; exit 1; }
  got=$(head -c $(( ${#2} / 2 )) "$f" | od -An -tx1 | tr -d ' \n')
  [ "$got" = "$2" ] || { echo "fresh-machine-check: $1 is not a valid file of its format (starts $got)" >&2; exit 1; }
  echo "fresh-machine-check: $1 written ($(stat -c %s "$f") bytes)"
}
check_magic cornell-box.exr 762f3101           # OpenEXR magic number
check_magic cornell-box.png 89504e470d0a1a0a   # PNG signature
step "README command 1 passed on a fresh Debian 12"

if [ "$run_tests" = 1 ]; then
  step "README command 2: $second_cmd"
  in_root "$second_cmd"
  step "README command 2 passed on a fresh Debian 12"
fi
for cmd in "${then_cmds[@]}"; do
  step "then: $cmd"
  in_root "$cmd"
done
step "done"
