#!/usr/bin/env python3
"""Measures `bdptref validate` as a classifier of port bugs (docs/validate.md, "Measured as a classifier").

    tools/validate_classifier.py [--budget 60] [--bugs a,b] [--false-alarm-runs 50] [--work DIR]
    tools/validate_classifier.py --in-place BUILD_DIR ...     # CI: patch this checkout, rebuild BUILD_DIR
    tools/validate_classifier.py --check-bugs                 # CI: every bug still applies (no build)

1. Copies the repository's tracked files to WORK/src and builds `bdptref` there (Release); with
   --in-place BUILD_DIR, patches this checkout itself (each file restored afterwards, also on
   Ctrl-C) and rebuilds `bdptref` in that configured build folder: only the patched file and the
   link are rebuilt, which keeps a CI run short.
2. For every bug of tools/port_bugs.py: applies it, rebuilds, runs
   `bdptref validate --self PORT --budget BUDGET` with the patched binary (the "port"), records
   whether the suite flagged it (exit 1), which scenes and the first failing depth, and reverts it.
3. With --false-alarm-runs K: the unpatched binary validated K times with distinct seeds
   (--seed-base 1 + 10^6 k: validate spaces its own renders 1000 apart), rotating the ports path, lt, bdpt: the share of runs that exit 1 is
   the suite's false-alarm rate, to be inside the binomial 99% interval of --alpha.

Prints a Markdown table and writes WORK/classifier.json. Exit status 0 when every bug was flagged
and the false alarms are inside their interval, 1 otherwise. Standard library only.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.dont_write_bytecode = True
from port_bugs import BUGS  # noqa: E402
from compare_calibration import binom_interval  # noqa: E402  (one binomial interval for both harnesses)


def copy_tree(work):
    src = os.path.join(work, "src")
    files = subprocess.run(["git", "-C", ROOT, "ls-files", "-z"], check=True, capture_output=True).stdout.split(b"\0")
    for f in files:
        if not f:
            continue
        rel = f.decode()
        a, b = os.path.join(ROOT, rel), os.path.join(src, rel)
        if not os.path.isfile(a):
            continue
        if os.path.isfile(b) and open(a, "rb").read() == open(b, "rb").read():
            continue
        os.makedirs(os.path.dirname(b), exist_ok=True)
        shutil.copy2(a, b)
    return src


def build(src, build_dir):
    if not os.path.isfile(os.path.join(build_dir, "build.ninja")):
        cmd = ["cmake", "-S", src, "-B", build_dir, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
               "-DBDPTREF_BUILD_TESTS=OFF", "-DBDPTREF_BUILD_PYTHON=OFF", "-DBDPTREF_BUILD_SHARED=OFF"]
        if shutil.which("ccache"):
            cmd.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    r = subprocess.run(["cmake", "--build", build_dir, "--target", "bdptref"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("validate_classifier.py: build failed:\n" + r.stdout[-3000:] + r.stderr[-3000:])


def validate(binary, src, port, budget, seed_base, out, spp=0):
    t = time.time()
    size = ["--spp", str(spp)] if spp > 0 else ["--budget", str(budget)]
    r = subprocess.run([binary, "validate", "--self", port] + size + ["--seed-base", str(seed_base),
                        "--suite", os.path.join(src, "scenes", "conformance", "suite.json"), "--drop-renders", "-q",
                        "--json", "-o", out], capture_output=True, text=True)
    seconds = time.time() - t
    try:
        report = json.loads(r.stdout)
    except ValueError:
        report = {"scenes": []}
    flagged = [s["name"] for s in report["scenes"] if s["verdict"] == "INCONSISTENT"]
    depths = {s["name"]: s.get("firstFailingDepth") for s in report["scenes"] if s["verdict"] == "INCONSISTENT"}
    return dict(exit=r.returncode, flagged=flagged, depths=depths, seconds=seconds,
                error=r.stderr[-500:] if r.returncode not in (0, 1) else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--budget", type=float, default=60)
    ap.add_argument("--spp", type=int, default=0, help="fixed samples per render instead of --budget (deterministic: CI)")
    ap.add_argument("--bugs", default="", help="comma-separated names (default: all; none: only the false-alarm runs)")
    ap.add_argument("--false-alarm-runs", type=int, default=0)
    ap.add_argument("--alpha", type=float, default=0.01, help="validate's default suite alpha")
    ap.add_argument("--work", default="/tmp/bdptref-classifier")
    ap.add_argument("--in-place", metavar="BUILD_DIR", default="",
                    help="patch this checkout and rebuild bdptref in BUILD_DIR (configured already)")
    ap.add_argument("--check-bugs", action="store_true",
                    help="only check that every bug's text occurs as often as tools/port_bugs.py says (CI)")
    a = ap.parse_args()
    if a.check_bugs:
        stale = ["%s: its text occurs %d times in %s (expected %d)" % (b["name"], n, b["file"], b.get("count", 1))
                 for b in BUGS
                 for n in [open(os.path.join(ROOT, b["file"])).read().count(b["old"])] if n != b.get("count", 1)]
        if stale:
            sys.exit("validate_classifier.py: update tools/port_bugs.py:\n  " + "\n  ".join(stale))
        print("validate_classifier.py: all %d bugs apply to this checkout" % len(BUGS))
        return 0
    names = [n for n in a.bugs.split(",") if n and a.bugs != "none"]
    unknown = [n for n in names if n not in {b["name"] for b in BUGS}]
    if unknown:
        sys.exit("validate_classifier.py: unknown bugs: " + ", ".join(unknown))
    bugs = [] if a.bugs == "none" else [b for b in BUGS if not names or b["name"] in names]

    os.makedirs(a.work, exist_ok=True)
    if a.in_place:
        src, build_dir = ROOT, os.path.abspath(a.in_place)
        if not os.path.isfile(os.path.join(build_dir, "build.ninja")) and not os.path.isfile(os.path.join(build_dir, "Makefile")):
            sys.exit("validate_classifier.py: --in-place %s is not a configured build folder" % a.in_place)
    else:
        src = copy_tree(a.work)
        build_dir = os.path.join(a.work, "build")
    binary = os.path.join(build_dir, "bdptref")
    results = []
    for bug in bugs:
        path = os.path.join(src, bug["file"])
        original = open(path).read()
        n = original.count(bug["old"])
        if n != bug.get("count", 1):
            results.append(dict(bug=bug["name"], port=bug["port"], exit=None, flagged=[], depths={}, seconds=0,
                                error="the bug's text occurs %d times in %s (expected %d): update tools/port_bugs.py"
                                      % (n, bug["file"], bug.get("count", 1))))
            continue
        try:
            with open(path, "w") as f:
                f.write(original.replace(bug["old"], bug["new"]))
            build(src, build_dir)
            r = validate(binary, src, bug["port"], a.budget, 1, os.path.join(a.work, "out", bug["name"]), a.spp)
        finally:
            with open(path, "w") as f:
                f.write(original)
        r.update(bug=bug["name"], port=bug["port"])
        results.append(r)
        print("%-36s %-5s exit %s  flagged: %s" % (bug["name"], bug["port"], r["exit"], ", ".join(
            "%s (depth %s)" % (s, r["depths"][s]) for s in r["flagged"]) or "-"), flush=True)

    build(src, build_dir)
    alarms = []
    ports = ["path", "lt", "bdpt"]
    for k in range(a.false_alarm_runs):
        r = validate(binary, src, ports[k % 3], a.budget, 1 + 1000000 * (k + 1), os.path.join(a.work, "out", "clean-%d" % k), a.spp)
        r.update(run=k, port=ports[k % 3])
        alarms.append(r)
        print("clean run %2d (%s): exit %s %s" % (k, ports[k % 3], r["exit"], ", ".join(r["flagged"])), flush=True)

    flagged = sum(1 for r in results if r["exit"] == 1)
    print("\n| bug | port | flagged | scenes (first failing depth) | seconds |\n|---|---|---|---|---|")
    for r in results:
        print("| %s | %s | %s | %s | %.0f |" % (r["bug"], r["port"], "yes" if r["exit"] == 1 else "**no** %s" % (r["error"] or ""),
                                              ", ".join("%s (%s)" % (s, r["depths"][s]) for s in r["flagged"]), r["seconds"]))
    ok = flagged == len(results)
    print("\nflagged %d of %d bugs (%.0f%%) at a budget of %g s" % (flagged, len(results), 100.0 * flagged / max(1, len(results)), a.budget))
    if alarms:
        n_alarm = sum(1 for r in alarms if r["exit"] == 1)
        no_verdict = sum(1 for r in alarms if r["exit"] not in (0, 1))
        lo, hi = binom_interval(len(alarms), a.alpha)
        inside = lo <= n_alarm <= hi
        ok = ok and inside and no_verdict == 0
        print("false alarms: %d of %d clean runs (99%% interval for alpha %g: %d..%d)%s; no verdict: %d; median %.0f s per run"
              % (n_alarm, len(alarms), a.alpha, lo, hi, "" if inside else " OUTSIDE", no_verdict,
                 sorted(r["seconds"] for r in alarms)[len(alarms) // 2]))
    with open(os.path.join(a.work, "classifier.json"), "w") as f:
        json.dump(dict(budget=a.budget, bugs=results, cleanRuns=alarms), f, indent=1)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
