#!/usr/bin/env python3
"""Measures `bdptref validate` as a classifier of port bugs (docs/validate.md, "Measured as a classifier").

    tools/validate_classifier.py [--budget 60] [--bugs a,b] [--false-alarm-runs 50] [--work DIR] [--strategy-layers]
    tools/validate_classifier.py --in-place BUILD_DIR ...     # CI: patch this checkout, rebuild BUILD_DIR
    tools/validate_classifier.py --check-bugs                 # CI: every bug still applies (no build)

1. Copies the repository's tracked files to WORK/src and builds `bdptref` there (Release); with
   --in-place BUILD_DIR, patches this checkout itself (each file restored afterwards, also on
   Ctrl-C and SIGTERM) and rebuilds `bdptref` in that configured build folder: only the patched
   file and the link are rebuilt, which keeps a CI run short.
2. For every bug of tools/port_bugs.py: applies it, rebuilds, runs
   `bdptref validate --self PORT --budget BUDGET` with the patched binary (the "port"), records
   whether the suite flagged it (exit 1), which scenes and the first failing depth, and reverts it.
   A bug marked control=True is an unbiased change (another correct sampling): it must NOT be flagged.
3. The diagnosis: for every flagged bug, the rank (1-based) of the bug's `term` in the report's
   "diagnosis" list (docs/diagnosis.md), and whether some scene of "diagnosisPerScene" names it
   first. Detection, top-1 and top-3 (among detected bugs) per port and overall.
4. With --false-alarm-runs K: the unpatched binary validated K times with distinct seeds
   (--seed-base 1 + 10^6 k: validate spaces its own renders 1000 apart), rotating the ports path, lt, bdpt: the share of runs that exit 1 is
   the suite's false-alarm rate, to be inside the binomial 99% interval of --alpha.

Prints Markdown tables and writes WORK/classifier.json. Exit status 0 when every bug was flagged,
no control was, and the false alarms are inside their interval, 1 otherwise (the diagnosis's
accuracy is reported, not enforced). --check-bugs also checks that every bug names exactly one term
of the catalogue (src/verify/validate_terms.cpp, the one source of the ids). Standard library only.
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.dont_write_bytecode = True
from port_bugs import BUGS  # noqa: E402
from compare_calibration import binom_interval  # noqa: E402  (one binomial interval for both harnesses)

PORTS = ["path", "lt", "bdpt"]


def catalogue_terms(root=ROOT):
    """The term ids of validate's catalogue: the first string of each `{"a.b", "...", ...}` entry."""
    text = open(os.path.join(root, "src", "verify", "validate_terms.cpp")).read()
    return re.findall(r'^\s*\{"([a-z0-9_]+(?:\.[a-z0-9_]+)+)",', text, re.M)


def bug_problems(bugs, root=ROOT):
    """What is wrong with the bug list against this checkout: stale text, missing or unknown terms."""
    terms = set(catalogue_terms(root))
    problems = [] if len(terms) >= 10 else ["found only %d term ids in src/verify/validate_terms.cpp" % len(terms)]
    names = [b["name"] for b in bugs]
    problems += ["%s: the name occurs %d times" % (n, names.count(n)) for n in sorted(set(names)) if names.count(n) > 1]
    for b in bugs:
        n = open(os.path.join(root, b["file"])).read().count(b["old"])
        if n != b.get("count", 1):
            problems.append("%s: its text occurs %d times in %s (expected %d)" % (b["name"], n, b["file"], b.get("count", 1)))
        if not isinstance(b.get("term"), str) or not b["term"]:
            problems.append("%s: no term= (one id of the term catalogue)" % b["name"])
        elif b["term"] not in terms:
            problems.append("%s: term %r is not in the catalogue (src/verify/validate_terms.cpp)" % (b["name"], b["term"]))
        if b.get("port") not in PORTS:
            problems.append("%s: port %r is not one of %s" % (b["name"], b.get("port"), ", ".join(PORTS)))
    return problems


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


def validate(binary, src, port, a, seed_base, out):
    t = time.time()
    size = ["--spp", str(a.spp)] if a.spp > 0 else ["--budget", str(a.budget)]
    scenes = ["--scenes", a.scenes] if a.scenes else []
    strategies = ["--strategy-layers"] if a.strategy_layers and port in ("bdpt", "path") else []
    r = subprocess.run([binary, "validate", "--self", port] + size + scenes + strategies + ["--alpha", repr(a.alpha), "--seed-base", str(seed_base),
                        "--suite", os.path.join(src, "scenes", "conformance", "suite.json"), "--drop-renders", "-q",
                        "--json", "-o", out], capture_output=True, text=True)
    seconds = time.time() - t
    try:
        report = json.loads(r.stdout)
    except ValueError:
        report = {"scenes": []}
    failing = [s for s in report.get("scenes", []) if s.get("verdict") == "INCONSISTENT"]
    return dict(exit=r.returncode, flagged=[s["name"] for s in failing], seconds=seconds,
                depths={s["name"]: s.get("firstFailingDepth") for s in failing},
                diagnosis=[d.get("term") for d in report.get("diagnosis", [])],
                perScene={d.get("scene"): d.get("term") for d in report.get("diagnosisPerScene", [])},
                error="" if r.returncode in (0, 1) else (r.stderr[-500:] or "; ".join(
                    "%s: %s" % (s["name"], s.get("message", s["verdict"])) for s in report.get("scenes", [])
                    if s.get("verdict") not in ("consistent", "INCONSISTENT", "skipped"))[:500]))


def score_diagnosis(result, term):
    """The rank of the bug's term in the ranked diagnosis (1-based, None if absent) and whether some
    failing scene alone names it first."""
    result["termRank"] = result["diagnosis"].index(term) + 1 if term in result["diagnosis"] else None
    result["perSceneNamesTerm"] = term in result["perScene"].values()
    return result


def run_bug(bug, src, build_dir, a):
    """Applies the bug, rebuilds, validates the patched binary, restores the file (also on Ctrl-C)."""
    path = os.path.join(src, bug["file"])
    original = open(path).read()
    n = original.count(bug["old"])
    if n != bug.get("count", 1):
        return dict(exit=None, flagged=[], depths={}, seconds=0, diagnosis=[], perScene={},
                    error="the bug's text occurs %d times in %s (expected %d): update tools/port_bugs.py"
                          % (n, bug["file"], bug.get("count", 1)))
    try:
        with open(path, "w") as f:
            f.write(original.replace(bug["old"], bug["new"]))
        build(src, build_dir)
        return validate(os.path.join(build_dir, "bdptref"), src, bug["port"], a, 1, os.path.join(a.work, "out", bug["name"]))
    finally:
        with open(path, "w") as f:
            f.write(original)


def rates(rows):
    """Detection, top-1 and top-3 of a group of (non-control) bug results."""
    detected = [r for r in rows if r["exit"] == 1]
    top = lambda k: sum(1 for r in detected if r["termRank"] is not None and r["termRank"] <= k)
    pct = lambda x, n: 100.0 * x / n if n else 0.0
    return dict(bugs=len(rows), detected=len(detected), detection=pct(len(detected), len(rows)),
                top1=top(1), top1Rate=pct(top(1), len(detected)), top3=top(3), top3Rate=pct(top(3), len(detected)),
                perScene=sum(1 for r in detected if r["perSceneNamesTerm"]))


def print_bug_table(results):
    print("\n| bug | port | term | flagged | rank of the term | diagnosis (best first) | scenes (first failing depth) | seconds |")
    print("|---|---|---|---|---|---|---|---|")
    for r in results:
        if r["exit"] not in (0, 1):
            flag = "**error** %s" % r["error"]
        else:
            flag = ("yes" if r["exit"] == 1 else "no") + (" (control)" if r["control"] else "")
            if (r["exit"] == 1) == r["control"]:
                flag = "**%s**" % flag
        print("| %s | %s | `%s` | %s | %s | %s | %s | %.0f |" % (
            r["bug"], r["port"], r["term"], flag, r.get("termRank") or "-", ", ".join(r["diagnosis"][:3]),
            ", ".join("%s (%s)" % (s, r["depths"][s]) for s in r["flagged"]), r["seconds"]))


def print_summary(summary, budget_text):
    print("\n| port | bugs | detected | detection | top-1 | top-3 | a failing scene alone names it |\n|---|---|---|---|---|---|---|")
    for port in PORTS + ["all"]:
        s = summary[port]
        if s["bugs"]:
            print("| %s | %d | %d | %.0f%% | %d (%.0f%%) | %d (%.0f%%) | %d |" % (
                port, s["bugs"], s["detected"], s["detection"], s["top1"], s["top1Rate"], s["top3"], s["top3Rate"], s["perScene"]))
    print("(top-1 and top-3 among the detected bugs; %s)" % budget_text)


def false_alarm_runs(binary, src, a):
    alarms = []
    for k in range(a.first_run, a.first_run + a.false_alarm_runs):
        port = PORTS[k % 3]
        r = validate(binary, src, port, a, 1 + 1000000 * (k + 1), os.path.join(a.work, "out", "clean-%d" % k))
        r.update(run=k, port=port)
        alarms.append(r)
        print("clean run %2d (%s): exit %s %s" % (k, port, r["exit"], ", ".join(r["flagged"])), flush=True)
    return alarms


def report_false_alarms(alarms, alpha):
    n_alarm = sum(1 for r in alarms if r["exit"] == 1)
    no_verdict = sum(1 for r in alarms if r["exit"] not in (0, 1))
    lo, hi = binom_interval(len(alarms), alpha)
    inside = lo <= n_alarm <= hi
    print("false alarms: %d of %d clean runs (99%% interval for alpha %g: %d..%d)%s; no verdict: %d; median %.0f s per run"
          % (n_alarm, len(alarms), alpha, lo, hi, "" if inside else " OUTSIDE", no_verdict,
             sorted(r["seconds"] for r in alarms)[len(alarms) // 2]))
    return inside and no_verdict == 0


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--budget", type=float, default=60)
    ap.add_argument("--spp", type=int, default=0, help="fixed samples per render instead of --budget (deterministic: CI)")
    ap.add_argument("--scenes", default="", help="only these suite scenes (comma-separated): a cheap check of one bug")
    ap.add_argument("--strategy-layers", action="store_true",
                    help="bidirectional and path-tracing ports also write their unweighted strategy layers (validate --strategy-layers)")
    ap.add_argument("--bugs", default="", help="comma-separated names (default: all; none: only the false-alarm runs)")
    ap.add_argument("--false-alarm-runs", type=int, default=0)
    ap.add_argument("--first-run", type=int, default=0,
                    help="number the false-alarm runs from this k (its seeds and port): two classifiers side by side "
                         "run disjoint sets, e.g. --false-alarm-runs 25 and --first-run 25 --false-alarm-runs 25")
    ap.add_argument("--alpha", type=float, default=0.01,
                    help="the suite's false-alarm rate, passed to validate (default 0.01, validate's own): with --scenes, "
                         "1 - (1 - a)^(k/K) tests k of a K-scene suite's scenes at the full suite's per-scene level")
    ap.add_argument("--work", default="/tmp/bdptref-classifier")
    ap.add_argument("--in-place", metavar="BUILD_DIR", default="",
                    help="patch this checkout and rebuild bdptref in BUILD_DIR (configured already)")
    ap.add_argument("--check-bugs", action="store_true",
                    help="only check that every bug applies to this checkout and names a catalogue term (CI)")
    return ap.parse_args()


def main():
    a = parse_args()
    # SIGTERM (a CI timeout, kill PID) unwinds like Ctrl-C: run_bug's `finally` restores the patched file.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    if a.check_bugs:
        problems = bug_problems(BUGS)
        if problems:
            sys.exit("validate_classifier.py: update tools/port_bugs.py:\n  " + "\n  ".join(problems))
        print("validate_classifier.py: all %d bugs (%d controls) apply to this checkout and name a catalogue term"
              % (len(BUGS), sum(1 for b in BUGS if b.get("control"))))
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
    results = []
    for bug in bugs:
        r = score_diagnosis(run_bug(bug, src, build_dir, a), bug.get("term"))
        r.update(bug=bug["name"], port=bug["port"], term=bug.get("term"), control=bool(bug.get("control")))
        results.append(r)
        print("%-40s %-5s exit %s  term %s rank %s  flagged: %s" % (bug["name"], bug["port"], r["exit"], r["term"], r["termRank"], ", ".join(
            "%s (depth %s)" % (s, r["depths"][s]) for s in r["flagged"]) or "-"), flush=True)

    build(src, build_dir)
    alarms = false_alarm_runs(os.path.join(build_dir, "bdptref"), src, a)

    real = [r for r in results if not r["control"]]
    controls = [r for r in results if r["control"]]
    summary = {p: rates([r for r in real if r["port"] == p]) for p in PORTS}
    summary["all"] = rates(real)
    budget_text = "--spp %d" % a.spp if a.spp > 0 else "a budget of %g s" % a.budget
    if results:
        print_bug_table(results)
        print_summary(summary, budget_text + (", scenes " + a.scenes if a.scenes else ""))
    ok = all(r["exit"] == 1 for r in real) and all(r["exit"] == 0 for r in controls)
    print("\nflagged %d of %d bugs (%.0f%%) at %s; controls flagged: %d of %d" % (
        summary["all"]["detected"], len(real), summary["all"]["detection"], budget_text,
        sum(1 for r in controls if r["exit"] == 1), len(controls)))
    if alarms:
        ok = report_false_alarms(alarms, a.alpha) and ok
    with open(os.path.join(a.work, "classifier.json"), "w") as f:
        json.dump(dict(budget=a.budget, spp=a.spp, scenes=a.scenes, summary=summary, bugs=results, cleanRuns=alarms), f, indent=1)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
