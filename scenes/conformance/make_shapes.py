#!/usr/bin/env python3
"""Renders the estimator shapes of the conformance suite (docs/validate.md, "Estimator shapes").

    scenes/conformance/make_shapes.py                       # every scene and estimator
    scenes/conformance/make_shapes.py layered-materials     # only these scenes
    scenes/conformance/make_shapes.py --seconds 2 --out /tmp/shapes   # a smoke test

A port of another estimator than the reference's (light tracing or BDPT against a path-traced
reference) can have pixels whose samples are far more heavy-tailed than the reference's: a glossy
coat seen at a grazing angle is a rare, very bright light-tracing sample, while the path tracer
samples it smoothly. Renders of a few tens of samples per pixel then all miss those samples and
look smooth, and the reference's shape does not say that they should not. So for every scene and
every estimator the scene lists other than its reference's, this renders a long bdptref render of
that estimator and keeps its mean, variances and counts: `compare --test-shape` reads from it the
per-sample relative variance C = (n - 1) v / m^2 of each pixel, which validate passes for the
port's estimator.

Each render takes about --seconds (default 40) on --threads (default 0: all cores), with spp a
power of two sized by a pilot, seed 2000 (the references use 1000, validate's renders 1..). The
file keeps only R, G, B, the variances and the count, in 32-bit floats: a variance of the mean in
half floats underflows (below 6e-8 it is 0, below 6e-5 it keeps few bits), and a dark pixel whose
samples are heavy-tailed then reads as smooth (docs/validate.md, "Estimator shapes"). suite.json
gets each scene's "shapes" entry. Options: --bdptref PATH (default build/bdptref); --same-spp
renders each shape again with the spp of the file it replaces (its header's command line), so that
a re-render changes only what was asked. Needs oiiotool (openimageio-tools).
"""
import argparse
import os
import shlex
import subprocess
import time

from make_references import HERE, ROOT, command, load_suite, save_suite

SEED = 2000
INTEGRATOR = {"path": "path", "light": "lt", "bidirectional": "bdpt"}
KEEP = "R,G,B,variance.R,variance.G,variance.B,count"


def render(bdptref, suite, scene, estimator, out, spp, threads):
    ref = dict(scene["referenceRender"], integrator=INTEGRATOR[estimator], spp=spp)
    ref.pop("mis", None)  # balance heuristic, bdptref's default
    cmd = command(bdptref, suite, dict(scene, referenceRender=ref), out, spp, threads)
    cmd = [c for c in cmd if c != "--depth-layers"]
    cmd[cmd.index("--seed") + 1] = str(SEED)
    t = time.time()
    subprocess.run(cmd, check=True, cwd=ROOT)
    return time.time() - t, cmd


def existing_spp(path):
    """The spp of an existing shape, from the command line in its header (None if unknown)."""
    if not os.path.exists(path):
        return None
    info = subprocess.run(["oiiotool", "--info", "-v", path], capture_output=True, text=True).stdout
    for line in info.splitlines():
        if "bdptref:commandLine" in line:
            words = line.split('"')[1].split() if '"' in line else line.split()
            for flag, word in zip(words, words[1:]):
                if flag == "--spp":
                    return int(word)
                if flag == "--sample-range":
                    lo, hi = word.split(":")
                    return int(hi) - int(lo)
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*")
    ap.add_argument("--bdptref", default="build/bdptref")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--seconds", type=float, default=40.0)
    ap.add_argument("--out", default=None, help="folder for the files (then suite.json is left alone)")
    ap.add_argument("--same-spp", action="store_true",
                    help="render each shape with the spp of the file it replaces (no pilot)")
    a = ap.parse_args()
    suite, scenes = load_suite("make_shapes.py", a.names)
    folder = a.out or os.path.join(ROOT, "reference-images", "conformance", "shapes")
    os.makedirs(folder, exist_ok=True)
    for scene in scenes:
        shapes = {}
        for est in scene["estimators"]:
            if INTEGRATOR[est] == scene["referenceRender"]["integrator"]:
                continue  # the reference's own shape
            out = os.path.join(folder, "%s.%s.exr" % (scene["name"], est))
            # Rendered beside the file and moved over it when complete: an interrupted run never
            # leaves a partial shape in its place.
            raw, tmp = out + ".render.exr", out + ".tmp.exr"
            spp = existing_spp(out) if a.same_spp else None
            if spp is None:
                pilot, _ = render(a.bdptref, suite, scene, est, raw, 16, a.threads)
                spp = 256
                while spp < 32768 and pilot * 2 * spp / 16 <= a.seconds:
                    spp *= 2
            seconds, cmd = render(a.bdptref, suite, scene, est, raw, spp, a.threads)
            subprocess.run(["oiiotool", "-a", raw, "--subimage", "0", "--ch", KEEP, "-d", "float",
                            "--compression", "zip", "-o", tmp], check=True)
            os.remove(raw)
            os.replace(tmp, out)
            print("make_shapes.py: %s %s: %d spp in %.0f s: %s" % (scene["name"], est, spp, seconds,
                  " ".join(shlex.quote(c) for c in cmd)), flush=True)
            shapes[est] = os.path.relpath(out, HERE)
        if shapes:
            scene["shapes"] = shapes
        else:
            scene.pop("shapes", None)
    if not a.out:
        save_suite(suite)


if __name__ == "__main__":
    main()
