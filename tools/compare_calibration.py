#!/usr/bin/env python3
"""Calibration of `bdptref compare` under H0: both images are correct renders (docs/compare.md).

    tools/compare_calibration.py [--bdptref build/bdptref] [--seeds 50] [--quick] [--out DIR] [--renders N]

For every scene x image size x estimator x spp it renders a pool of independent images (distinct
seeds), then compares test image i of one pool with reference image i of another (every
estimator pairing, equal and unequal sample counts): the pairs of one cell are independent, so
under H0 their global p-values must be uniform. Per cell it prints the false alarms at
alpha = 0.01 and 0.05 with the central binomial 99% interval of their count, the number of
"insufficient samples" answers (exit 2, no verdict), which of the two tests raised the alarms at
0.05 (local / bias, each at its Sidak level 1 - 0.95^(1/2)), the mean bias-test z over the pairs
(0 under H0) and the Kolmogorov-Smirnov distances of the p-values from Uniform(0, 1): two-sided D
and one-sided D+ = max(F_n(x) - x) (p-values leaning towards 0), with their 1% critical values.
A cell fails when a false-alarm count is outside its interval or D+ exceeds its critical value; a
conservative cell (large D, small D+) is reported, not failed. A final line pools every cell
(cells share image pools, so that line is not an independent test). Exit status: 0 when no cell
fails, 1 otherwise. The images are rendered once per setting and seed (float32 EXR, as a renderer
writes them) into --out, or a temporary folder that is removed at the end. Standard library only.
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# name: (scene file, extra render options); lights of every kind, and an environment.
SCENES = {
    "cornell-box": ("scenes/cornell-box.gltf", []),                     # area lights
    "sphere-point-light": ("scenes/sphere-point-light.gltf", []),       # a point light
    "mis-zoo": ("scenes/mis-zoo.gltf", ["--env", "0.3,0.35,0.4"]),      # point, spot, directional, environment
    "env-sphere": ("scenes/env-sphere.glb", ["--env", "1,1,1"]),        # environment only
}
ESTIMATORS = {
    "pt": ["--integrator", "path"],
    "lt": ["--integrator", "lt"],
    "bdpt-balance": ["--integrator", "bdpt", "--mis", "balance"],
    "bdpt-power": ["--integrator", "bdpt", "--mis", "power"],
}


def binom_interval(n, p, level=0.99):
    """Central interval [lo, hi] of Binomial(n, p) counts holding at least `level` (exact cdf)."""
    pmf = [math.comb(n, k) * p ** k * (1 - p) ** (n - k) for k in range(n + 1)]
    tail = (1 - level) / 2
    lo, acc = 0, 0.0
    while lo < n and acc + pmf[lo] <= tail:
        acc += pmf[lo]
        lo += 1
    hi, acc = n, 0.0
    while hi > 0 and acc + pmf[hi] <= tail:
        acc += pmf[hi]
        hi -= 1
    return lo, hi


def ks_distance(ps):
    """Kolmogorov-Smirnov distance of the sample ps from Uniform(0, 1)."""
    xs = sorted(ps)
    n = len(xs)
    return max(max((i + 1) / n - x, x - i / n) for i, x in enumerate(xs)) if n else 0.0


def ks_plus(ps):
    """One-sided KS distance max(F_n(x) - x): how far the p-values lean towards 0 (false alarms)."""
    xs = sorted(ps)
    n = len(xs)
    return max(max((i + 1) / n - x for i, x in enumerate(xs)), 0.0) if n else 0.0


def ks_plus_critical(n, alpha=0.01):
    """Asymptotic critical value of the one-sided KS distance, sqrt(-ln(alpha) / 2) / sqrt(n) (Stephens' correction)."""
    return math.sqrt(-0.5 * math.log(alpha)) / (math.sqrt(n) + 0.12 + 0.11 / math.sqrt(n)) if n else 1.0


def ks_critical(n, alpha=0.01):
    """Asymptotic critical value of the KS distance (with the small-sample correction of Stephens)."""
    c = math.sqrt(-0.5 * math.log(alpha / 2))
    return c / (math.sqrt(n) + 0.12 + 0.11 / math.sqrt(n)) if n else 1.0


def render(a, scene, size, est, spp, seed, out):
    path, opts = SCENES[scene]
    cmd = [a.bdptref, "render", os.path.join(ROOT, path), "--width", str(size), "--height", str(size), "--spp", str(spp),
           "--seed", str(seed), "--max-depth", str(a.max_depth), "-q", "--no-preview", "-o", out] + opts + ESTIMATORS[est]
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise SystemExit("calibration: render failed: %s\n%s" % (" ".join(cmd), r.stderr[-1500:]))


def compare(a, tests, ref):
    r = subprocess.run([a.bdptref, "compare", "--json"] + tests + [ref], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        j = json.loads(r.stdout)
    except ValueError:
        j = {}
    if r.returncode == 2:
        return None  # no verdict (insufficient samples): counted separately
    if r.returncode not in (0, 1) or "tests" not in j:
        raise SystemExit("calibration: compare failed (%d) on %s %s\n%s" % (r.returncode, " ".join(tests), ref, r.stderr[-1500:]))
    t = j["tests"]
    return t["pGlobal"], t["pLocal"], t["pBias"], sum(t["biasZ"]) / 3.0


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--bdptref", default=os.path.join(ROOT, "build", "bdptref"))
    p.add_argument("--seeds", type=int, default=None, help="independent pairs per cell (default 50; --quick: 30)")
    p.add_argument("--scenes", default=",".join(SCENES))
    p.add_argument("--estimators", default=",".join(ESTIMATORS))
    p.add_argument("--sizes", default="16,64", help="image sizes (default 16,64)")
    p.add_argument("--test-spp", default="4,16,64", help="sample counts of the test images")
    p.add_argument("--ref-spp", default="64,1024", help="sample counts of the references")
    p.add_argument("--max-depth", type=int, default=5)
    p.add_argument("--quick", action="store_true", help="reduced matrix for CI: cornell-box, 16x16, pt and bdpt-balance, "
                                                        "test 4 and 16 spp, reference 64 spp, 30 seeds")
    p.add_argument("--out", default=None, help="keep the renders here (default: a temporary folder)")
    p.add_argument("--renders", type=int, default=1, help="test side: N >= 2 plain renders per pair (compare T1 ... TN REF); "
                                                          "default 1: one image with variance layers")
    a = p.parse_args()
    if a.quick:
        a.scenes, a.estimators, a.sizes, a.test_spp, a.ref_spp = "cornell-box", "pt,bdpt-balance", "16", "4,16", "64"
        a.seeds = a.seeds or 30
    a.seeds = a.seeds or 50
    if a.renders < 1:
        raise SystemExit("calibration: --renders must be >= 1")
    scenes = a.scenes.split(",")
    ests = a.estimators.split(",")
    sizes = [int(s) for s in a.sizes.split(",")]
    test_spp = [int(s) for s in a.test_spp.split(",")]
    ref_spp = [int(s) for s in a.ref_spp.split(",")]
    for s in scenes:
        if s not in SCENES:
            raise SystemExit("calibration: unknown scene %r" % s)
    for e in ests:
        if e not in ESTIMATORS:
            raise SystemExit("calibration: unknown estimator %r" % e)
    out = a.out or tempfile.mkdtemp(prefix="bdptref-calibration-")
    os.makedirs(out, exist_ok=True)

    def pool(scene, size, est, spp, role, count):
        """Renders (once) the pool of images of one setting; test seeds 1.., reference seeds 100001.."""
        base = 1 if role == "test" else 100001
        files = []
        for i in range(count):
            f = os.path.join(out, "%s-%d-%s-%dspp-%s-%d.exr" % (scene, size, est, spp, role, i))
            if not os.path.exists(f):
                render(a, scene, size, est, spp, base + i, f)
            files.append(f)
        return files

    all_p, bad = [], 0
    if a.renders > 1:
        print("test side: %d plain renders per pair (compare T1 ... T%d REF)\n" % (a.renders, a.renders))
    print("| scene | size | test | ref | spp test/ref | verdicts | no verdict | FA @0.01 (99% interval) | FA @0.05 (99% interval) "
          "| local/bias FA @0.05 | mean bias z | KS D / D+ (1% crit.) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for scene in scenes:
        for size in sizes:
            for et in ests:
                for er in ests:
                    for st in test_spp:
                        for sr in ref_spp:
                            tests = pool(scene, size, et, st, "test", a.seeds * a.renders)
                            refs = pool(scene, size, er, sr, "ref", a.seeds)
                            res = [compare(a, tests[i * a.renders:(i + 1) * a.renders], r) for i, r in enumerate(refs)]
                            verdicts = [x for x in res if x is not None]
                            ps = [x[0] for x in verdicts]
                            n = len(ps)
                            fa1 = sum(1 for x in ps if x < 0.01)
                            fa5 = sum(1 for x in ps if x < 0.05)
                            # the two tests at their own Sidak level: 1 - 0.95^(1/2)
                            lvl = 1 - math.sqrt(0.95)
                            loc5 = sum(1 for x in verdicts if x[1] < lvl)
                            bia5 = sum(1 for x in verdicts if x[2] < lvl)
                            zs = [x[3] for x in verdicts]
                            zm = sum(zs) / n if n else 0.0
                            zse = math.sqrt(sum((z - zm) ** 2 for z in zs) / (n - 1) / n) if n > 1 else 0.0
                            i1, i5 = binom_interval(n, 0.01), binom_interval(n, 0.05)
                            ks, kc = ks_distance(ps), ks_critical(n)
                            kp, kpc = ks_plus(ps), ks_plus_critical(n)
                            # A cell with no verdict at all raised no false alarm: every answer was exit 2.
                            # Failing: a false-alarm count outside its interval, or p-values leaning
                            # towards 0 (one-sided KS); a conservative test (p-values leaning towards 1,
                            # two-sided KS only) is reported, not failed.
                            ok = n == 0 or (i1[0] <= fa1 <= i1[1] and i5[0] <= fa5 <= i5[1] and kp <= kpc)
                            bad += not ok
                            all_p += ps
                            print("| %s | %d | %s | %s | %d/%d | %d | %d | %d (%d-%d) | %d (%d-%d) | %d/%d | %+.2f +- %.2f | %s |" % (
                                scene, size, et, er, st, sr, n, len(res) - n, fa1, i1[0], i1[1], fa5, i5[0], i5[1], loc5, bia5,
                                zm, zse, ("%.3f / %.3f (%.3f / %.3f)" % (ks, kp, kc, kpc)) if n else "-") +
                                  ("" if ok else " **outside**"), flush=True)
    n = len(all_p)
    i1, i5 = binom_interval(n, 0.01), binom_interval(n, 0.05)
    print("\nall cells: %d verdicts, false alarms %d at 0.01 (interval %d-%d), %d at 0.05 (interval %d-%d), KS %.4f (crit. %.4f); "
          "%d cell(s) outside their intervals" % (n, sum(x < 0.01 for x in all_p), i1[0], i1[1], sum(x < 0.05 for x in all_p),
                                                  i5[0], i5[1], ks_distance(all_p), ks_critical(n), bad))
    if not a.out:
        shutil.rmtree(out, ignore_errors=True)
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
