#!/usr/bin/env python3
"""Renders the references of the conformance suite (scenes/conformance/suite.json, docs/validate.md).

    scenes/conformance/make_references.py                  # every scene of the suite
    scenes/conformance/make_references.py cornell-box      # only these
    scenes/conformance/make_references.py --spp-scale 0.01 --out /tmp/refs   # a smoke test

Options: --bdptref PATH (default build/bdptref; relative paths are from the repository root), --threads N (default 0: all cores), --out DIR
(default: where suite.json says), --spp-scale F.

Each reference is `bdptref render` with the scene's settings (size, maxDepth, environment) and its
`referenceRender` (integrator, MIS, spp), seed 1000 (validate's renders use seeds from 1), and
--depth-layers, so that validate can say at which depth a port goes wrong. The EXR header keeps
the exact command. The exact film state (the EXR's second part, for --resume and merge) is then
dropped with oiiotool (openimageio-tools, installed by tools/install-deps.sh): validate reads
only the mean, the variances and the counts, and the file shrinks to a third. Standard library only.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SUITE = os.path.join(HERE, "suite.json")


def load_suite(tool, names):
    """suite.json, and its scenes to work on: those named (each must be in the suite), else all."""
    with open(SUITE) as f:
        suite = json.load(f)
    known = [s["name"] for s in suite["scenes"]]
    for n in names:
        if n not in known:
            sys.exit("%s: no scene %r in the suite (it has: %s)" % (tool, n, ", ".join(known)))
    return suite, [s for s in suite["scenes"] if not names or s["name"] in names]


def save_suite(suite):
    """suite.json as the scripts write it (two-space indent, one newline at the end), replaced whole."""
    with open(SUITE + ".tmp", "w") as f:
        f.write(json.dumps(suite, indent=2, ensure_ascii=False) + "\n")
    os.replace(SUITE + ".tmp", SUITE)


SEED = 1000


def command(bdptref, suite, scene, out, spp, threads):
    # Repository paths (the command runs in the repository root), so the headers name no checkout.
    rel = lambda p: os.path.relpath(os.path.join(HERE, p), ROOT)
    ref = scene["referenceRender"]
    cmd = [bdptref, "render", rel(scene["scene"]), "-o", out, "--width", str(suite["width"]),
           "--height", str(suite["height"]), "--spp", str(spp), "--seed", str(SEED),
           "--max-depth", str(scene.get("maxDepth", 8)), "--integrator", ref["integrator"],
           "--depth-layers", "--no-preview", "-q", "--threads", str(threads)]
    if "mis" in ref:
        cmd += ["--mis", ref["mis"]]
    if "envMap" in scene:
        cmd += ["--env-map", rel(scene["envMap"])]
        if scene.get("envScale", 1.0) != 1.0:
            cmd += ["--env-scale", repr(scene["envScale"])]
    if scene.get("env"):
        cmd += ["--env", scene["env"]]
    return cmd


def strip_exact_state(path):
    """Keeps the EXR's first part (mean, variances, counts, depth layers; every header attribute)."""
    tmp = path + ".part0.exr"
    subprocess.run(["oiiotool", "-a", path, "--subimage", "0", "-o", tmp], check=True)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*")
    ap.add_argument("--bdptref", default="build/bdptref")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--out", default=None)
    ap.add_argument("--spp-scale", type=float, default=1.0)
    a = ap.parse_args()
    suite, scenes = load_suite("make_references.py", a.names)
    if a.out:
        os.makedirs(a.out, exist_ok=True)  # bdptref render writes into an existing folder only
    for scene in scenes:
        target = os.path.normpath(os.path.join(HERE, scene["reference"]))
        out = os.path.abspath(os.path.join(a.out, os.path.basename(target))) if a.out else target
        out = os.path.relpath(out, ROOT) if out.startswith(ROOT + os.sep) else out
        spp = max(2, int(round(scene["referenceRender"]["spp"] * a.spp_scale)))
        cmd = command(a.bdptref, suite, scene, out, spp, a.threads)
        print("make_references.py:", " ".join(shlex.quote(c) for c in cmd), flush=True)
        t = time.time()
        subprocess.run(cmd, check=True, cwd=ROOT)
        strip_exact_state(os.path.join(ROOT, out))
        print("make_references.py: %s done in %.0f s" % (scene["name"], time.time() - t), flush=True)


if __name__ == "__main__":
    main()
