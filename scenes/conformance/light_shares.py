#!/usr/bin/env python3
"""Measures each kind of light's share of a conformance scene's image (docs/diagnosis.md, "Light shares").

    scenes/conformance/light_shares.py                  # every suite scene lit by two kinds of light or more
    scenes/conformance/light_shares.py lights-room      # only these
    scenes/conformance/light_shares.py --spp 256 --dry-run   # print, do not write suite.json

A term that scales one kind of light (683 lm/W or 4 pi on punctual lights, pi on a directional
light) changes a scene lit by several kinds by 1 - s (1 - f), s that kind's share of the image.
Light transport is linear in the emitters, so the image is the sum of the images each kind alone
gives: this renders the scene once per kind with the other kinds switched off (emissive materials
black, punctual nodes without their light, no environment) with its reference's estimator (a path
tracer misses a point light's caustics), size and maximum depth, and writes each kind's share of the image mean, averaged over R, G and B as
validate averages the channels' relative biases, into suite.json as "lightShares". Kinds: area
(emissive triangles), punctual (point and spot lights), directional, environment. Scenes lit by
one kind get no entry (its share is 1).

Emitter shares: a light tracer whose double-sided emitters' direction density is not halved scales
their light by 1/2 from depth 1 on (depth 0 joins the light's point to the camera, no direction).
For scenes with a double-sided emissive material this renders the scene with only those emitters
on, with depth layers, and writes the share of the image mean they light from depth 1, (mean -
depth 0) over the whole scene's mean (the sum of each kind's render), into suite.json as "emitterShares": {"doubleSidedFromDepth1": s}. Options: --bdptref PATH (default build/bdptref), --spp N
(default 1024), --threads N. Needs oiiotool (openimageio-tools). Standard library only.
"""
import argparse
import copy
import json
import math
import os
import re
import subprocess
import tempfile

from make_references import HERE, ROOT, command, load_suite, save_suite

SEED = 3000  # the references use 1000, the shapes 2000, validate's renders 1..


def emits(material):
    strength = material.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
    return any(c > 0 for c in material.get("emissiveFactor", [0, 0, 0])) and strength > 0


def light_kinds(gltf, scene):
    """The kinds of light in a scene: its glTF and the suite's environment settings."""
    kinds = set()
    if any(emits(m) for m in gltf.get("materials", [])):
        kinds.add("area")
    lights = gltf.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for node in gltf.get("nodes", []):
        ref = node.get("extensions", {}).get("KHR_lights_punctual")
        if ref is not None:
            kinds.add("directional" if lights[ref["light"]]["type"] == "directional" else "punctual")
    if scene.get("env") or scene.get("envMap"):
        kinds.add("environment")
    return kinds


def only(gltf, kind):
    """The glTF with every light not of `kind` switched off (the environment is a render option);
    kind "doubleSided": only the double-sided emissive materials."""
    g = copy.deepcopy(gltf)
    if kind != "area":
        for m in g.get("materials", []):
            if not (kind == "doubleSided" and m.get("doubleSided", False)):
                m["emissiveFactor"] = [0, 0, 0]
    lights = g.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for node in g.get("nodes", []):
        ext = node.get("extensions", {})
        ref = ext.get("KHR_lights_punctual")
        if ref is None:
            continue
        own = "directional" if lights[ref["light"]]["type"] == "directional" else "punctual"
        if own != kind:
            del ext["KHR_lights_punctual"]
    return g


def channel_stats(path, layer=""):
    """Per channel (R, G, B) of the beauty or of a layer ("depth0."): the image mean and the variance of that mean."""
    channels = ",".join(layer + c for c in ("R", "G", "B", "variance.R", "variance.G", "variance.B"))
    out = subprocess.run(["oiiotool", path, "--ch", channels, "--printstats"], capture_output=True, text=True, check=True).stdout
    avg = [float(v) for v in re.search(r"Stats Avg:\s*([^\n]*)", out).group(1).split()[:6]]
    res = re.search(r"(\d+)\s*x\s*(\d+)", out)
    pixels = int(res.group(1)) * int(res.group(2))
    return avg[:3], [v / pixels for v in avg[3:6]]  # var(image mean) = mean of the pixels' variances of their means / N


def render_kind(a, suite, scene, gltf, kind, folder, depth0=False):
    """The kind's (channel means, variances of the means); with depth0, also depth 0's."""
    # The copy lies beside the original: its buffers and textures are found by the same relative URIs.
    src = os.path.normpath(os.path.join(HERE, scene["scene"]))
    fd, variant = tempfile.mkstemp(prefix=".%s.only-%s." % (scene["name"], kind), suffix=".gltf", dir=os.path.dirname(src))
    out = os.path.join(folder, "%s.%s.exr" % (scene["name"], kind))
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(only(gltf, kind), f)
        s = dict(scene, scene=os.path.relpath(variant, HERE), referenceRender=dict(scene["referenceRender"], spp=a.spp))
        if kind != "environment":
            s.pop("env", None), s.pop("envMap", None)
        cmd = command(a.bdptref, suite, s, out, a.spp, a.threads)
        cmd = [c for c in cmd if depth0 or c != "--depth-layers"]
        cmd[cmd.index("--seed") + 1] = str(SEED)
        subprocess.run(cmd, check=True, cwd=ROOT)
        return (channel_stats(out), channel_stats(out, "depth0.")) if depth0 else channel_stats(out)
    finally:
        os.remove(variant)


def shares_of(a, suite, scene):
    with open(os.path.normpath(os.path.join(HERE, scene["scene"]))) as f:
        gltf = json.load(f)
    kinds = sorted(light_kinds(gltf, scene))
    if len(kinds) < 2:
        return None, None
    with tempfile.TemporaryDirectory() as folder:
        stats = {k: render_kind(a, suite, scene, gltf, k, folder) for k in kinds}
    shares, sigmas = {}, {}
    for k in kinds:
        per_channel, var = [], []
        for c in range(3):
            total = sum(stats[j][0][c] for j in kinds)
            if total <= 0:
                continue
            s = stats[k][0][c] / total
            per_channel.append(s)
            # delta method: s = m_k / (m_k + m_rest); ds/dm_k = (1 - s) / total, ds/dm_rest = -s / total
            rest = sum(stats[j][1][c] for j in kinds if j != k)
            var.append(((1 - s) ** 2 * stats[k][1][c] + s ** 2 * rest) / total ** 2)
        shares[k] = sum(per_channel) / len(per_channel)
        sigmas[k] = math.sqrt(sum(var)) / len(var)
    return shares, sigmas


def double_sided_share(a, suite, scene):
    """The share of the image mean that the double-sided emitters light from depth 1 (None: none)."""
    with open(os.path.normpath(os.path.join(HERE, scene["scene"]))) as f:
        gltf = json.load(f)
    if not any(emits(m) and m.get("doubleSided", False) for m in gltf.get("materials", [])):
        return None
    with tempfile.TemporaryDirectory() as folder:
        (mean, _), (depth0, _) = render_kind(a, suite, scene, gltf, "doubleSided", folder, depth0=True)
        kinds = sorted(light_kinds(gltf, scene))
        whole = [sum(t) for t in zip(*(render_kind(a, suite, scene, gltf, k, folder)[0] for k in kinds))]
    per_channel = [(mean[c] - depth0[c]) / whole[c] for c in range(3) if whole[c] > 0]
    return sum(per_channel) / len(per_channel)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*")
    ap.add_argument("--bdptref", default="build/bdptref")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--dry-run", action="store_true", help="print the shares, leave suite.json as it is")
    a = ap.parse_args()
    suite, scenes = load_suite("light_shares.py", a.names)
    for scene in scenes:
        double_sided = double_sided_share(a, suite, scene)
        if double_sided is None:
            scene.pop("emitterShares", None)
        else:
            scene["emitterShares"] = {"doubleSidedFromDepth1": round(double_sided, 4)}
            print("light_shares.py: %s: double-sided emitters from depth 1 %.4f (%d spp)" % (scene["name"], double_sided, a.spp), flush=True)
        shares, sigmas = shares_of(a, suite, scene)
        if shares is None:
            scene.pop("lightShares", None)
            continue
        scene["lightShares"] = {k: round(v, 4) for k, v in shares.items()}
        print("light_shares.py: %s: %s (%d spp)" % (scene["name"], ", ".join(
            "%s %.4f +- %.4f" % (k, shares[k], sigmas[k]) for k in shares), a.spp), flush=True)
    if not a.dry_run:
        save_suite(suite)


if __name__ == "__main__":
    main()
