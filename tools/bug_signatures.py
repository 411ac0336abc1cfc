#!/usr/bin/env python3
"""Bug signatures of the conformance suite (docs/diagnosis.md, "Bug signatures").

    tools/bug_signatures.py make --from WORK[,WORK2] [--out scenes/conformance/signatures.json]
    tools/bug_signatures.py leave-one-out --from WORK[,WORK2] [--weights 0,4] [--bdptref build/bdptref] [--suite S]

WORK is a tools/validate_classifier.py work folder: WORK/out/<bug>/report.json is the validate
report of bdptref patched with that bug of tools/port_bugs.py, playing its port at the budget.

make: writes, for every bug the suite flagged (controls excluded), the term it breaks, the
estimator it played and each scene's result (failed, ratio test / reference, 95% interval): the
file suite.json names under "signatures", which `bdptref validate` and `bdptref diagnose` match a
port's results against.

leave-one-out: for every flagged bug, `bdptref diagnose report.json --leave-out BUG` (its own
signature ignored; the signatures of the other bugs, of the same term too, kept) and the rank of
its term; prints detection, top-1 and top-3 per port and overall, for each --weights value of
the signature weight (0: the diagnosis without signatures). Standard library only.
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.dont_write_bytecode = True
from port_bugs import BUGS  # noqa: E402

ESTIMATOR = {"path": "path", "lt": "light", "bdpt": "bidirectional"}


def reports(work_dirs):
    """(bug, report path) of every bug with a report in the work folders."""
    by_name = {b["name"]: b for b in BUGS}
    for work in work_dirs:
        out = os.path.join(work, "out")
        for name in sorted(os.listdir(out)) if os.path.isdir(out) else []:
            path = os.path.join(out, name, "report.json")
            if name in by_name and os.path.isfile(path):
                yield by_name[name], path


def scene_results(report):
    scenes = {}
    for s in report["scenes"]:
        beauty = [l for l in s.get("layers", []) if l["layer"] == "beauty"]
        if not beauty or s["verdict"] not in ("consistent", "INCONSISTENT") or s.get("lowPower"):
            continue
        b = beauty[0]
        scenes[s["name"]] = {"failed": s["verdict"] == "INCONSISTENT", "ratio": 1 + b["relativeBias"],
                             "low": 1 + b["relativeBias95"][0], "high": 1 + b["relativeBias95"][1]}
        # A bidirectional port's strategy classes (docs/validate.md, "Strategy classes"): "depth2.nextEvent".
        tested, failed = set(), set()
        for l in s.get("strategyClassLayers", []):
            if l["verdict"] != "no verdict":
                tested.add(l["layer"].split(".", 1)[1])
                if l["verdict"] == "inconsistent":
                    failed.add(l["layer"].split(".", 1)[1])
        if tested:
            scenes[s["name"]].update(testedClasses=sorted(tested), failedClasses=sorted(failed))
    return scenes


def make(a):
    signatures = []
    for bug, path in reports(a.work):
        report = json.load(open(path))
        if bug.get("control") or report.get("exitCode") != 1:
            continue
        signatures.append({"bug": bug["name"], "term": bug["term"], "estimator": ESTIMATOR[bug["port"]],
                           "scenes": scene_results(report)})
    doc = {"about": "What each port bug of tools/port_bugs.py did to this suite, as bdptref patched with it "
                    "played its port at the default budget (tools/bug_signatures.py make; docs/diagnosis.md, "
                    "\"Bug signatures\"). A scene is listed when it had a verdict of full power.",
           "signatures": signatures}
    with open(a.out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print("bug_signatures.py: %d signatures written to %s" % (len(signatures), a.out))


def rank_of(a, path, bug, weight):
    extra = (["--signatures", a.signatures] if a.signatures else []) + ["--suite", a.suite]
    r = subprocess.run([a.bdptref, "diagnose", path, "--leave-out", bug["name"], "--signature-weight", str(weight),
                        "--json"] + extra, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("bug_signatures.py: bdptref diagnose %s failed: %s" % (path, r.stderr.strip()))
    terms = [e["term"] for e in json.loads(r.stdout)["diagnosis"]]
    return terms.index(bug["term"]) + 1 if bug["term"] in terms else None


def leave_one_out(a):
    weights = [float(w) for w in a.weights.split(",")]
    rows = []
    for bug, path in reports(a.work):
        if bug.get("control"):
            continue
        report = json.load(open(path))
        flagged = report.get("exitCode") == 1
        ranks = [rank_of(a, path, bug, w) if flagged else None for w in weights]
        rows.append((bug, flagged, ranks))
    print("| port | bugs | detected | " + " | ".join("top-1 / top-3 (weight %g)" % w for w in weights) + " |")
    print("|---|---|---|" + "---|" * len(weights))
    for port in ("path", "lt", "bdpt", None):
        sel = [r for r in rows if port is None or r[0]["port"] == port]
        det = [r for r in sel if r[1]]
        cells = []
        for k in range(len(weights)):
            top1 = sum(1 for r in det if r[2][k] == 1)
            top3 = sum(1 for r in det if r[2][k] is not None and r[2][k] <= 3)
            cells.append("%d / %d (%.0f%% / %.0f%%)" % (top1, top3, 100.0 * top1 / max(1, len(det)), 100.0 * top3 / max(1, len(det))))
        print("| %s | %d | %d (%.0f%%) | %s |" % (port or "all", len(sel), len(det), 100.0 * len(det) / max(1, len(sel)), " | ".join(cells)))
    if a.details:
        for bug, flagged, ranks in rows:
            print("%-44s %-5s %-28s %s" % (bug["name"], bug["port"], bug["term"], "not flagged" if not flagged else " ".join(str(r) for r in ranks)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", choices=["make", "leave-one-out"])
    ap.add_argument("--from", dest="work", required=True, type=lambda s: [p for p in s.split(",") if p],
                    help="classifier work folders, comma-separated")
    ap.add_argument("--out", default=os.path.join(ROOT, "scenes", "conformance", "signatures.json"))
    ap.add_argument("--weights", default="0,%g" % 4.0, help="signature weights to compare (leave-one-out)")
    ap.add_argument("--bdptref", default=os.path.join(ROOT, "build", "bdptref"))
    ap.add_argument("--suite", default=os.path.join(ROOT, "scenes", "conformance", "suite.json"),
                    help="leave-one-out: the suite whose scene terms the diagnosis reads (default: this checkout's, "
                         "not the copy a classifier run's reports name)")
    ap.add_argument("--signatures", default="", help="leave-one-out: this signatures file instead of the suite's")
    ap.add_argument("--details", action="store_true", help="one line per bug with its term's ranks")
    a = ap.parse_args()
    make(a) if a.mode == "make" else leave_one_out(a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
