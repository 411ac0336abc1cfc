#!/usr/bin/env python3
"""Measures BDPT's strategy shares of each conformance scene (docs/diagnosis.md, "Strategy shares").

    scenes/conformance/strategy_shares.py                  # every suite scene a bidirectional port renders
    scenes/conformance/strategy_shares.py depth-limit-glossy
    scenes/conformance/strategy_shares.py --spp 64 --dry-run   # print, do not write suite.json

A bidirectional port that gets one strategy's contribution wrong after its MIS weight changes the
image by that strategy's weighted share s: a factor f on it gives 1 - s (1 - f). Two such terms
have a share of their own: light tracing's splats (every t = 1 strategy, `lt.splat_normalisation`:
f = 1/4096 when they are divided by the pixel count again), and the emitter hits of the deepest
depth (s = 0, t = maxDepth + 2, which a camera subpath one vertex short of maxDepth + 2 vertices
never samples: `subpath.length_limit`, f = 0), and light tracing at the deepest depth (s =
maxDepth + 1, t = 1, which a light subpath one vertex short never samples: the same term). This renders the scene once with bdptref's BDPT
(--strategies: each (s, t) strategy's weighted layer), its size and maximum depth, and writes
into suite.json, as "strategyShares", each share of the image mean averaged over R, G and B as
validate averages the channels' relative biases: "lightTracing", "deepestEmitterHit" and
"deepestLightTracing"; and the other strategy classes' shares, "emitterHit" (s = 0), "nextEvent"
(s = 1, t >= 2) and "connections" (s >= 2, t >= 2): a class whose share is nil (no emitter a ray
can hit, no connection below maxDepth 2) hides no error, compared or not.
Options: --bdptref PATH (default build/bdptref), --spp N (default 512), --threads N. Needs
oiiotool (openimageio-tools). Standard library only.
"""
import argparse
import os
import re
import subprocess
import tempfile

from make_references import ROOT, command, load_suite, save_suite

SEED = 4000  # the references use 1000, the shapes 2000, the light shares 3000, validate's renders 1..


def channel_means(path):
    """{channel name: image mean} of the first part of an EXR."""
    info = subprocess.run(["oiiotool", "--info", "-v", path], capture_output=True, text=True, check=True).stdout
    names = [c.strip() for c in re.search(r"channel list:\s*([^\n]*)", info).group(1).split(",")]
    stats = subprocess.run(["oiiotool", path, "--printstats"], capture_output=True, text=True, check=True).stdout
    avg = [float(v) for v in re.search(r"Stats Avg:\s*([^\n]*)", stats).group(1).split()[:len(names)]]
    return dict(zip(names, avg))


def strategy_class(s, t):
    """The class of strategy (s, t), as validate's strategyClassOf (src/verify/validate_strategy_classes.cpp)."""
    if t == 1:
        return "lightTracing"
    if s == 0:
        return "emitterHit"
    return "nextEvent" if s == 1 else "connections"


def shares_of(a, suite, scene):
    with tempfile.TemporaryDirectory() as folder:
        out = os.path.join(folder, scene["name"] + ".exr")
        s = dict(scene, referenceRender={"integrator": "bdpt", "spp": a.spp})  # the default MIS, as a port validates
        cmd = [c for c in command(a.bdptref, suite, s, out, a.spp, a.threads) if c != "--depth-layers"]
        cmd[cmd.index("--seed") + 1] = str(SEED)
        subprocess.run(cmd + ["--strategies", "--exr-compression", "none"], check=True, cwd=ROOT)
        means = channel_means(out)
    deepest = "s0t%d" % (scene.get("maxDepth", 8) + 2)
    deepest_light = "s%dt1" % (scene.get("maxDepth", 8) + 1)
    weighted = re.compile(r"(s(\d+)t(\d+))\.weighted\.([RGB])$")
    shares = {k: [] for k in ("lightTracing", "deepestEmitterHit", "deepestLightTracing", "emitterHit", "nextEvent", "connections")}
    for c in "RGB":
        total = means[c]
        if total <= 0:
            continue
        sums = dict.fromkeys(shares, 0.0)
        for key, v in means.items():
            m = weighted.match(key)
            if not m or m.group(4) != c:
                continue
            sums[strategy_class(int(m.group(2)), int(m.group(3)))] += v
            if m.group(1) in (deepest, deepest_light):
                sums["deepestEmitterHit" if m.group(1) == deepest else "deepestLightTracing"] += v
        for k in shares:
            shares[k].append(sums[k] / total)
    return {k: sum(v) / len(v) for k, v in shares.items() if v}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*")
    ap.add_argument("--bdptref", default="build/bdptref")
    ap.add_argument("--spp", type=int, default=512)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--dry-run", action="store_true", help="print the shares, leave suite.json as it is")
    a = ap.parse_args()
    suite, scenes = load_suite("strategy_shares.py", a.names)
    for scene in scenes:
        if "bidirectional" not in scene["estimators"]:
            scene.pop("strategyShares", None)
            continue
        shares = shares_of(a, suite, scene)
        scene["strategyShares"] = {k: round(v, 4) for k, v in shares.items()}
        print("strategy_shares.py: %s: %s (%d spp)" % (scene["name"], ", ".join(
            "%s %.4f" % (k, v) for k, v in shares.items()), a.spp), flush=True)
    if not a.dry_run:
        save_suite(suite)


if __name__ == "__main__":
    main()
