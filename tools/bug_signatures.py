#!/usr/bin/env python3
"""Bug signatures of the conformance suite (docs/diagnosis.md, "Bug signatures").

    tools/bug_signatures.py make --from WORK[,WORK2] [--out scenes/conformance/signatures.json]
    tools/bug_signatures.py leave-one-out --from WORK[,WORK2] [--weights 0,4] [--bdptref build/bdptref] [--suite S]
                            [--require 0.95,0.70,0.90]    # CI: exit 1 below these detection, top-1, top-3
    tools/bug_signatures.py pack --from WORK[,WORK2] [--out scenes/conformance/bug-reports.json.gz]
    tools/bug_signatures.py check      # CI: the shipped signatures are what `make` gives from the shipped reports

WORK is a tools/validate_classifier.py work folder: WORK/out/<bug>/report.json is the validate
report of bdptref patched with that bug of tools/port_bugs.py, playing its port at the budget;
or a file written by `pack` (ending in .json.gz): every bug's report with only what the
diagnosis reads (each scene's verdict and its beauty, depth and strategy-class layers), so that
the leave-one-out of the shipped reports (scenes/conformance/bug-reports.json.gz, docs/diagnosis.md)
runs in seconds, without the two hours of validate runs that made them. A bug's report in a later
folder or file is merged into its earlier one scene by scene: a classifier run of new scenes alone
(--scenes) adds them, and the bug counts as flagged when either run flagged it.

make: writes, for every bug the suite flagged (controls excluded), the term it breaks, the
estimator it played and each scene's result (failed, ratio test / reference, 95% interval): the
file suite.json names under "signatures", which `bdptref validate` and `bdptref diagnose` match a
port's results against.

leave-one-out: for every flagged bug, `bdptref diagnose report.json --leave-out BUG` (its own
signature ignored; the signatures of the other bugs, of the same term too, kept) and the rank of
its term; prints detection, top-1 and top-3 per port and overall, for each --weights value of
the signature weight (0: the diagnosis without signatures). With --require D,T1,T3, exits 1 when
detection of all bugs is below D, or top-1 or top-3 of the detected ones below T1 or T3 at the
last weight (the issue's targets: a change of the diagnosis that loses a bug's term shows).
Standard library only.
"""
import argparse
import gzip
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.dont_write_bytecode = True
from port_bugs import BUGS  # noqa: E402

ESTIMATOR = {"path": "path", "lt": "light", "bdpt": "bidirectional"}


def merged(a, b):
    """Report a with the scenes of report b (a run of other scenes, or the same ones again) put in:
    b's scene replaces a's of the same name; the bug is flagged when either run flagged it."""
    out = dict(a)
    names = {s["name"]: i for i, s in enumerate(a["scenes"])}
    scenes = list(a["scenes"])
    for s in b["scenes"]:
        if s["verdict"] == "skipped" and s["name"] in names:
            continue  # b did not run it
        if s["name"] in names:
            scenes[names[s["name"]]] = s
        else:
            scenes.append(s)
    out["scenes"] = scenes
    out["exitCode"] = 1 if 1 in (a.get("exitCode"), b.get("exitCode")) else b.get("exitCode")
    return out


def load_reports(sources):
    """{bug name: report} from classifier work folders and packed files; a bug's later reports are
    merged into its earlier one scene by scene (`merged`): a run of new scenes alone adds to them."""
    found = {}

    def add(name, report):
        found[name] = merged(found[name], report) if name in found else report

    for source in sources:
        if source.endswith(".json.gz"):
            with gzip.open(source, "rt") as f:
                for name, report in sorted(json.load(f)["reports"].items()):
                    add(name, report)
            continue
        out = os.path.join(source, "out")
        for name in sorted(os.listdir(out)) if os.path.isdir(out) else []:
            path = os.path.join(out, name, "report.json")
            if os.path.isfile(path):
                with open(path) as f:
                    add(name, json.load(f))
    return found


def reports(sources):
    """(bug, report) of every bug of tools/port_bugs.py with a report in the sources, in the list's order."""
    found = load_reports(sources)
    return [(b, found[b["name"]]) for b in BUGS if b["name"] in found]


LAYER_KEYS = ("layer", "verdict", "relativeBias", "relativeBias95", "meanRelativeBias", "meanRelativeBias95")
SCENE_KEYS = ("name", "verdict", "lowPower", "firstFailingDepth")


def stripped(report):
    """What `bdptref diagnose` reads of a report (diagnosisInputFromJson), and its exit code."""
    scenes = []
    for s in report["scenes"]:
        e = {k: s[k] for k in SCENE_KEYS if k in s}
        for key in ("layers", "strategyClassLayers"):
            if s.get(key):
                e[key] = [{k: l[k] for k in LAYER_KEYS if k in l} for l in s[key]]
        scenes.append(e)
    return {"estimator": report["estimator"], "exitCode": report.get("exitCode"), "suite": report.get("suite", ""),
            "scenes": scenes}


def pack(a):
    reps = {b["name"]: stripped(r) for b, r in reports(a.work)}
    doc = {"about": "validate reports of bdptref patched with each bug of tools/port_bugs.py playing its port "
                    "(tools/validate_classifier.py), stripped to what the diagnosis reads (tools/bug_signatures.py pack)",
           "reports": reps}
    tmp = a.out + ".tmp"
    with gzip.open(tmp, "wt") as f:
        json.dump(doc, f, separators=(",", ":"), sort_keys=True)
    os.replace(tmp, a.out)
    print("bug_signatures.py: %d reports packed into %s (%d bytes)" % (len(reps), a.out, os.path.getsize(a.out)))


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


def signatures_of(sources):
    signatures = []
    for bug, report in reports(sources):
        if bug.get("control") or report.get("exitCode") != 1:
            continue
        signatures.append({"bug": bug["name"], "term": bug["term"], "estimator": ESTIMATOR[bug["port"]],
                           "scenes": scene_results(report)})
    return signatures


def check(a):
    """The shipped signatures.json holds exactly the signatures of the shipped reports."""
    conformance = os.path.join(ROOT, "scenes", "conformance")
    shipped = json.load(open(os.path.join(conformance, "signatures.json")))["signatures"]
    made = json.loads(json.dumps(signatures_of(a.work or [os.path.join(conformance, "bug-reports.json.gz")])))
    if shipped != made:
        names = lambda sigs: {s["bug"] for s in sigs}
        sys.exit("bug_signatures.py check: scenes/conformance/signatures.json is not what the shipped reports give "
                 "(tools/bug_signatures.py make --from scenes/conformance/bug-reports.json.gz); only in the file: %s; "
                 "only in the reports: %s; %d differ" % (sorted(names(shipped) - names(made)), sorted(names(made) - names(shipped)),
                                                       sum(1 for x, y in zip(shipped, made) if x != y)))
    print("bug_signatures.py check: the %d shipped signatures are the shipped reports'" % len(shipped))


def make(a):
    signatures = signatures_of(a.work)
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
    with tempfile.TemporaryDirectory() as folder:
        for bug, report in reports(a.work):
            if bug.get("control"):
                continue
            path = os.path.join(folder, bug["name"] + ".json")
            with open(path, "w") as f:
                json.dump(report, f)
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
    failed = False
    if a.require:
        need = [float(v) for v in a.require.split(",")]
        det = [r for r in rows if r[1]]
        got = [len(det) / max(1, len(rows)), sum(1 for r in det if r[2][-1] == 1) / max(1, len(det)),
               sum(1 for r in det if r[2][-1] is not None and r[2][-1] <= 3) / max(1, len(det))]
        for name, g, n in zip(("detection", "top-1", "top-3"), got, need):
            if g < n:
                print("bug_signatures.py: %s %.1f%% is below the required %.1f%%" % (name, 100 * g, 100 * n))
                failed = True
    if a.details:
        for bug, flagged, ranks in rows:
            print("%-44s %-5s %-28s %s" % (bug["name"], bug["port"], bug["term"], "not flagged" if not flagged else " ".join(str(r) for r in ranks)))
    return failed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", choices=["make", "leave-one-out", "pack", "check"])
    ap.add_argument("--from", dest="work", default=[], type=lambda s: [p for p in s.split(",") if p],
                    help="classifier work folders or packed .json.gz files, comma-separated (later ones win)")
    ap.add_argument("--out", default="", help="make: default scenes/conformance/signatures.json; "
                                              "pack: default scenes/conformance/bug-reports.json.gz")
    ap.add_argument("--weights", default="0,%g" % 4.0, help="signature weights to compare (leave-one-out)")
    ap.add_argument("--bdptref", default=os.path.join(ROOT, "build", "bdptref"))
    ap.add_argument("--suite", default=os.path.join(ROOT, "scenes", "conformance", "suite.json"),
                    help="leave-one-out: the suite whose scene terms the diagnosis reads (default: this checkout's, "
                         "not the copy a classifier run's reports name)")
    ap.add_argument("--signatures", default="", help="leave-one-out: this signatures file instead of the suite's")
    ap.add_argument("--details", action="store_true", help="one line per bug with its term's ranks")
    ap.add_argument("--require", default="", help="leave-one-out: D,T1,T3: exit 1 below this detection, top-1 or top-3 (fractions)")
    a = ap.parse_args()
    conformance = os.path.join(ROOT, "scenes", "conformance")
    if a.mode == "check":
        check(a)
        return 0
    if not a.work:
        ap.error("--from is required")
    if a.mode == "make":
        a.out = a.out or os.path.join(conformance, "signatures.json")
        make(a)
    elif a.mode == "pack":
        a.out = a.out or os.path.join(conformance, "bug-reports.json.gz")
        pack(a)
    elif leave_one_out(a):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
