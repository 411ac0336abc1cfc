#!/usr/bin/env python3
"""Calibration of `bdptref compare` against a renderer nobody here wrote (docs/compare.md, "Foreign renderers").

    tools/foreign_calibration.py --peer PEER_DIR [--bdptref build/bdptref] [--sets 20] [--renders 8]
                                 [--spp 64] [--size 64] [--estimators pt,lt,bpt] [--references 4] [--out DIR] [--jobs 2]

PEER_DIR is the SmallVCM peer folder (build.sh, scene4.gltf; never part of the project). The harness
builds the peer into --out, renders bdptref references of the peer's scene 4 (one per kind: a BDPT
reference of 1024 spp, a path-traced one of 4096 spp and a light-traced one of 4096 spp, by
default; --ref-spp changes the three; --references of each, distinct seeds, used in turn by the
sets), then for every peer algorithm (`-a pt`, `-a lt`, `-a bpt`)
and seed set k = 1..--sets renders --renders plain images of --spp samples with distinct seeds and
runs `bdptref compare T1 ... TN REF --samples-per-render SPP --json` against the reference of the
matching kind and against the path-traced one. Each set is compared twice: as rendered (H0: a
correct renderer; an alarm is a false alarm) and with every render scaled by 1.01 (a 1% bias, which
must be flagged in every set). Per cell it prints the false alarms at alpha = 0.01 with the central
binomial 99% interval of their count, the sets without a verdict, the 1% scale's detections, which
test raised each false alarm, and the mean bias-test z; writes foreign.md and foreign.json into
--out. Exit status 0 when every cell's false alarms are inside the interval and the 1% scale is
flagged in every set, 1 otherwise.

The peer writes PFM files top row first: they are flipped on the way to EXR (oiiotool). Its path
length L (segments) is bdptref's --max-depth L - 1. Standard library only, plus oiiotool.
"""

import argparse
import json
import math
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.dont_write_bytecode = True  # no __pycache__ in the repository
from compare_calibration import binom_interval  # noqa: E402  (the same 99% interval as compare's own calibration)
# peer algorithm -> (bdptref integrator of the matching kind, its name in the table)
KINDS = {"pt": "path", "lt": "lt", "bpt": "bdpt"}


def log(msg):
    print("[foreign-calibration] " + msg, file=sys.stderr, flush=True)


def run(cmd, ok=(0,)):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode not in ok:
        raise SystemExit("foreign-calibration: command failed (%d): %s\n%s" % (r.returncode, " ".join(cmd), r.stderr[-2000:]))
    return r


def reference(a, kind, index):
    path = os.path.join(a.out, "ref-%s-%d-%d.exr" % (kind, a.ref_spp[kind], index))
    if not os.path.exists(path):
        log("reference %s %d, %d spp" % (kind, index, a.ref_spp[kind]))
        run([a.bdptref, "render", a.scene, "--integrator", kind, "--spp", str(a.ref_spp[kind]), "--width", str(a.size),
             "--height", str(a.size), "--max-depth", str(a.segments - 1), "--seed", str(987654 + index), "--threads",
             str(a.jobs), "--depth-layers", "-o", path])
    return path


def no_emitter_mask(a, ref):
    """1 where the reference has no depth-0 light (no emitter seen directly), 0 elsewhere: the peer's
    light tracer never connects a light's own point to the camera, so it lacks that light (a real
    difference of that estimator, docs/compare.md, "Foreign renderers")."""
    mask = os.path.join(a.out, "mask-no-emitter.exr")
    if not os.path.exists(mask):
        run(["oiiotool", ref, "--ch", "depth0.R", "--mulc", "1e30", "--clamp:min=0:max=1", "--mulc", "-1", "--addc", "1",
             "-d", "float", "-o", mask])
    return mask


def peer_render(a, algorithm, seed):
    """One peer render as a float EXR (flipped), and its copy scaled by 1.01."""
    base = os.path.join(a.out, "renders", "%s-n%d-%d" % (algorithm, a.peer_threads, seed))
    exr, scaled = base + ".exr", base + ".x1.01.exr"
    if not os.path.exists(scaled):
        pfm = base + ".pfm"
        run([a.peer_exe, "-s", "4", "-a", algorithm, "-r", str(a.size), "-n", str(a.peer_threads), "-l", str(a.segments), "-i",
             str(a.spp), "--seed", str(seed), "-o", pfm])
        run(["oiiotool", pfm, "--flip", "-d", "float", "-o", exr])
        run(["oiiotool", exr, "--mulc", "1.01", "-d", "float", "-o", scaled])
        os.remove(pfm)
    return exr, scaled


def compare(a, tests, ref, mask):
    extra = ["--mask", mask] if mask else []
    r = run([a.bdptref, "compare"] + tests + [ref, "--samples-per-render", str(a.spp), "--json"] + extra, ok=(0, 1, 2))
    if "share noise" in r.stderr:
        return {"exit": 2, "refused": True, "p": None, "local": None, "bias": None, "z": None, "tested": 0,
                "flagged": 0, "sentence": r.stderr.strip()}
    j = json.loads(r.stdout)
    t = j.get("tests", {})
    zs = [z for z in t.get("biasZ", []) if z is not None]
    wb = [b for b in t.get("weightedRelativeBias", []) if b is not None]
    return {"relBias": sum(wb) / len(wb) if wb else None,"exit": r.returncode, "p": t.get("pGlobal"), "local": t.get("pLocal"), "bias": t.get("pBias"),
            "z": sum(zs) / len(zs) if zs else None, "tested": j.get("pixels", {}).get("tested"),
            "flagged": len(j.get("flaggedPixels", [])), "sentence": j.get("sentence", "")}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--peer", required=True, help="the SmallVCM peer folder (build.sh, scene4.gltf)")
    p.add_argument("--bdptref", default=os.path.join(ROOT, "build", "bdptref"))
    p.add_argument("--sets", type=int, default=20, help="seed sets per cell")
    p.add_argument("--renders", type=int, default=8, help="renders per set")
    p.add_argument("--spp", type=int, default=64, help="samples per peer render")
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--segments", type=int, default=10, help="peer path length; bdptref --max-depth is one less")
    p.add_argument("--estimators", default="pt,lt,bpt")
    p.add_argument("--ref-spp", default="path=4096,lt=4096,bdpt=1024")
    p.add_argument("--peer-threads", type=int, default=1, help="the peer's -n (it seeds thread i with seed + i)")
    p.add_argument("--seed-spacing", type=int, default=0,
                   help="distance between the seeds of consecutive renders (default: --peer-threads, so that no two "
                        "renders share a stream; 1 with --peer-threads 2 shows compare refusing renders that share noise)")
    p.add_argument("--references", type=int, default=4, help="references per kind (distinct seeds), used in turn")
    p.add_argument("--alpha", type=float, default=0.01)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--out", default="/tmp/foreign-calibration")
    a = p.parse_args()
    a.out = os.path.abspath(a.out)
    a.bdptref = os.path.abspath(a.bdptref)
    a.scene = os.path.join(a.peer, "scene4.gltf")
    a.seed_spacing = a.seed_spacing or a.peer_threads
    a.ref_spp = {k: int(v) for k, v in (kv.split("=") for kv in a.ref_spp.split(","))}
    os.makedirs(os.path.join(a.out, "renders"), exist_ok=True)
    a.peer_exe = run(["bash", os.path.join(a.peer, "build.sh"), os.path.join(a.out, "peer-build")]).stdout.strip().splitlines()[-1]
    algorithms = a.estimators.split(",")
    # Several references per kind, set k against reference k mod --references: one reference's own
    # unlucky pixels would otherwise be shared by every set, and the sets would not be independent.
    refs = {k: [reference(a, k, i) for i in range(a.references)] for k in sorted({KINDS[al] for al in algorithms} | {"path"})}

    cells = []
    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for algorithm in algorithms:
            seeds = [[1 + (k * a.renders + j) * a.seed_spacing for j in range(a.renders)] for k in range(a.sets)]
            log("%s: %d sets x %d renders of %d spp" % (algorithm, a.sets, a.renders, a.spp))
            renders = [list(pool.map(lambda s: peer_render(a, algorithm, s), ss)) for ss in seeds]
            mask = no_emitter_mask(a, refs["path"][0]) if algorithm == "lt" else None
            for kind in sorted({KINDS[algorithm], "path"}):
                jobs = [(rs, refs[kind][k % a.references]) for k, rs in enumerate(renders)]
                plain = list(pool.map(lambda j: compare(a, [x for x, _ in j[0]], j[1], mask), jobs))
                scaled = list(pool.map(lambda j: compare(a, [y for _, y in j[0]], j[1], mask), jobs))
                cells.append({"peer": algorithm, "reference": kind, "masked": bool(mask), "plain": plain, "scaled": scaled})
                log("  against %s: %d alarms, %d of %d scaled flagged" % (
                    kind, sum(c["exit"] == 1 for c in plain), sum(c["exit"] == 1 for c in scaled), len(scaled)))

    failed = False
    lines = ["| peer | reference | sets | refused: shared noise | verdicts | false alarms at %g (99%% interval) | by local / bias | mean bias z | pooled relative bias | 1%% scale flagged |" % a.alpha,
             "|---|---|---|---|---|---|---|---|---|---|"]
    for c in cells:
        verdicts = [x for x in c["plain"] if x["exit"] in (0, 1)]
        alarms = [x for x in verdicts if x["exit"] == 1]
        lo, hi = binom_interval(len(verdicts), a.alpha)
        by_local = sum(1 for x in alarms if x["local"] is not None and x["bias"] is not None and x["local"] <= x["bias"])
        zs = [x["z"] for x in verdicts if x["z"] is not None]
        mean_z = sum(zs) / len(zs) if zs else float("nan")
        flagged = sum(1 for x in c["scaled"] if x["exit"] == 1)
        # The sets' tile-weighted relative biases pooled: their mean and its standard error from their
        # spread (the sets share --references references, so this understates the references' part).
        rb = [x["relBias"] for x in verdicts if x.get("relBias") is not None]
        rb_mean = sum(rb) / len(rb) if rb else float("nan")
        rb_se = math.sqrt(sum((x - rb_mean) ** 2 for x in rb) / (len(rb) - 1) / len(rb)) if len(rb) > 1 else float("nan")
        # Renders refused for shared noise carry no verdict either way (a set-up error, not a pass).
        ok = lo <= len(alarms) <= hi and flagged == len([x for x in c["scaled"] if not x.get("refused")])
        failed = failed or not ok
        refused = sum(1 for x in c["plain"] if x.get("refused"))
        lines.append("| %s | %s %d spp | %d | %d | %d | %d (%d-%d)%s | %d / %d | %+.2f | %+.3f%% +- %.3f%% | %d of %d |" % (
            c["peer"] + (" (no emitter seen directly)" if c["masked"] else ""), c["reference"], a.ref_spp[c["reference"]],
            len(c["plain"]), refused, len(verdicts), len(alarms), lo, hi,
            "" if lo <= len(alarms) <= hi else " **outside**", by_local, len(alarms) - by_local, mean_z, 100 * rb_mean,
            100 * rb_se, flagged,
            len(c["scaled"])))
    table = "\n".join(lines)
    print(table)
    with open(os.path.join(a.out, "foreign.md"), "w") as f:
        f.write("%d renders of %d spp per set, %dx%d, %d segments (bdptref --max-depth %d), peer -n %d, seeds %d apart\n\n%s\n" % (
            a.renders, a.spp, a.size, a.size, a.segments, a.segments - 1, a.peer_threads, a.seed_spacing, table))
    with open(os.path.join(a.out, "foreign.json"), "w") as f:
        json.dump(cells, f, indent=1)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
