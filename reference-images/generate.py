#!/usr/bin/env python3
"""Regenerates the converged reference images of the shipped scenes and their manifest.

    reference-images/generate.py                 # every scene in SCENES (about 2 minutes each)
    reference-images/generate.py cornell-box     # only these (the others' entries are kept)
    reference-images/generate.py --list          # the names

Options: --bdptref PATH (default build/bdptref), --out DIR (default: this folder),
--spp-scale F (multiply every spp, e.g. 0.01 for a smoke test), --threads N,
--checks-only (update the check settings in the manifest without rendering).

For each scene it runs `bdptref render` (its exact command is recorded), reads the summary that
`render --stats` writes, and rewrites MANIFEST.json (read by tests/scenes/test_references.cpp)
and MANIFEST.md (for people) from all entries. To add a scene, add a line to SCENES and run the
script with its name. Uses only the Python 3 standard library.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
WIDTH = HEIGHT = 64
REFERENCE_SEED = 1000  # the checks use other seeds: compare warns about equal seeds
CHECK_SEED = 7

# name: scene file, options that define the image (besides size and seed), the reference's
# estimator and spp, and the check: a quick render by another estimator (or another MIS
# heuristic) that the tests compare against the reference. `reference` names another entry's
# image when the scene is the same content (cornell-box.glb is cornell-box.gltf in a GLB).
SCENES = {
    "cornell-box": dict(scene="scenes/cornell-box.gltf", options=[], integrator="path", spp=8192,
                        check=dict(integrator="bdpt", options=[], spp=32)),
    "cornell-box-glb": dict(scene="scenes/cornell-box.glb", options=[], reference="cornell-box",
                            check=dict(integrator="bdpt", options=[], spp=32)),
    "cornell-small-light": dict(scene="scenes/cornell-small-light.gltf", options=[], integrator="path", spp=8192,
                                check=dict(integrator="bdpt", options=[], spp=32)),
    "furnace-box": dict(scene="scenes/furnace-box.gltf", options=[], integrator="path", spp=8192,
                        check=dict(integrator="bdpt", options=[], spp=32)),
    "sphere-point-light": dict(scene="scenes/sphere-point-light.gltf", options=[], integrator="path", spp=2048,
                               check=dict(integrator="bdpt", options=[], spp=32)),
    # env-sphere has no lights: its documented environment (scenes/README.md) is part of the image.
    "env-sphere": dict(scene="scenes/env-sphere.glb", options=["--env", "1,1,1"], integrator="path", spp=8192,
                       check=dict(integrator="bdpt", options=[], spp=32)),
    # Point, spot and directional lights seen through glass and a mirror: only BDPT samples every
    # path here (a path tracer cannot reach a delta light through a delta BSDF, light tracing cannot
    # see through one), so the check is BDPT with the power heuristic against a balance reference.
    "mis-zoo": dict(scene="scenes/mis-zoo.gltf", options=[], integrator="bdpt", mis="balance", spp=256,
                    check=dict(integrator="bdpt", options=["--mis", "power"], spp=32)),
    # The benchmark scenes (bench/README.md). Veach's MIS scene and the 1M-triangle grid are
    # path-traced references checked by BDPT; the slit-lit room and the caustic are where a path
    # tracer is slow (the light is reached through a narrow gap / only through glass), so their
    # references are BDPT-balance checked by BDPT-power, like mis-zoo.
    "veach-mis": dict(scene="scenes/veach-mis.gltf", options=[], integrator="path", spp=4096,
                      check=dict(integrator="bdpt", options=[], spp=32)),
    "sphere-grid": dict(scene="scenes/sphere-grid.glb", options=[], integrator="path", spp=1024,
                        check=dict(integrator="bdpt", options=[], spp=32)),
    # 256 spp: the light comes through a slit, and a BDPT sample's relative variance is about 11 per
    # pixel (both estimators): at 128 spp a pixel holds about 11 effective samples, and compare's
    # neighbourhood rule found only 1013 of 4096 pixels with 10 (no verdict); at 32, 242.
    "narrow-gap": dict(scene="scenes/narrow-gap.gltf", options=[], integrator="bdpt", mis="balance", spp=2048,
                       check=dict(integrator="bdpt", options=["--mis", "power"], spp=256)),
    "caustic-glass": dict(scene="scenes/caustic-glass.gltf", options=[], integrator="bdpt", mis="balance", spp=2048,
                          check=dict(integrator="bdpt", options=["--mis", "power"], spp=32)),
    # Real-content features together (scenes/generate.py gltf_features): a normal-mapped floor,
    # MASK and BLEND cut-outs, COLOR_0, and an emissive-textured light.
    "gltf-features": dict(scene="scenes/gltf-features.gltf", options=[], integrator="path", spp=8192,
                          check=dict(integrator="bdpt", options=[], spp=32)),
    # Lit only by an HDR environment map with a small sun (scenes/generate.py env_map_outdoor):
    # option values under scenes/ are repository paths (the test resolves them the same way).
    "env-map-outdoor": dict(scene="scenes/env-map-outdoor.gltf", options=["--env-map", "scenes/env-map-sky.hdr"],
                            integrator="path", spp=8192, check=dict(integrator="bdpt", options=[], spp=32)),
    # Albedo 0.999: paths run to the depth limit, so it is kept at 16 bounces. Check at 128 spp: a
    # light-tracing sample's relative variance is about 6 per pixel here (a pixel receives splats
    # from few of the light paths), so 32 spp hold about 5 effective samples, too few for compare
    # (no pixel had 10; at 128, 4095 of 4096 do).
    "white-box": dict(scene="scenes/white-box.gltf", options=["--max-depth", "16"], integrator="path", spp=512,
                      check=dict(integrator="lt", options=[], spp=128)),
    # Volume absorption (KHR_materials_volume) in a smooth and a rough glass object under a large
    # area light: the coloured caustics are wide enough for a path tracer (per second it beat BDPT
    # here: median RSE 6.8% at 256 spp in 6.4 s against BDPT's 4.8% in 17 s).
    "absorbing-glass": dict(scene="scenes/absorbing-glass.gltf", options=[], integrator="path", spp=16384,
                            check=dict(integrator="bdpt", options=[], spp=32)),
}


def render_command(bdptref, name, entry, spp, threads, out_dir):
    cmd = [bdptref, "render", os.path.join(ROOT, entry["scene"]), "--width", str(WIDTH), "--height", str(HEIGHT),
           "--integrator", entry["integrator"], "--spp", str(spp), "--seed", str(REFERENCE_SEED), "-q",
           "-o", os.path.join(out_dir, name + ".exr"), "--preview", os.path.join(out_dir, name + ".png")]
    if "mis" in entry:
        cmd += ["--mis", entry["mis"]]
    if threads:
        cmd += ["--threads", str(threads)]
    return cmd + repo_paths(entry["options"])


def repo_paths(options):
    """Option values naming files of the repository (scenes/...) as paths the renderer can open."""
    return [os.path.join(ROOT, o) if o.startswith("scenes/") else o for o in options]


def write_markdown(path, manifest):
    lines = [
        "# Reference images",
        "",
        "Converged renders of the shipped scenes at %dx%d, written by `reference-images/generate.py`" % (WIDTH, HEIGHT),
        "(do not edit this file or MANIFEST.json by hand). Each EXR holds the mean, the variance of the",
        "mean, the counts and the exact film state; its header records every setting, the scene hash,",
        "the command line (`bdptref:commandLine`) and the render time (docs/exr.md, docs/ground-truth.md).",
        "`tests/scenes/test_references.cpp` renders each scene quickly with the *check* estimator and",
        "requires `compare` (which accounts for the reference's own variance) to find it consistent.",
        "",
        "Relative standard error (RSE): per pixel sqrt(mean variance of the mean) / mean, median and",
        "95th percentile over the pixels; `image`: of the average of the whole image.",
        "",
        "| scene | reference | estimator | spp | render time | threads | RSE median | RSE p95 | RSE image | check |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, e in manifest["references"].items():
        check = "%s, %d spp, seed %d" % (" ".join([e["check"]["integrator"]] + e["check"]["options"]),
                                         e["check"]["spp"], e["check"]["seed"])
        lines.append("| %s | `%s` | %s | %d | %.1f s | %d | %.4f | %.4f | %.2e | %s |" % (
            name, e["reference"], e["integrator"] + (" " + e["mis"] if e.get("mis") else ""), e["spp"],
            e["renderSeconds"], e["threads"], e["medianRelativeStandardError"], e["p95RelativeStandardError"],
            e["imageRelativeStandardError"], check))
    lines += ["", "Commands (relative to the repository root; `bdptref` is build/bdptref):", ""]
    for name, e in manifest["references"].items():
        lines.append("- %s: `%s`" % (name, e["command"]))
    lines.append("")
    with open(path, "w") as f:
        f.write("\n".join(lines))


def save(out_dir, manifest):
    """Writes MANIFEST.json (atomically) and MANIFEST.md; called after every scene."""
    manifest_path = os.path.join(out_dir, "MANIFEST.json")
    manifest["references"] = dict(sorted(manifest["references"].items()))
    with open(manifest_path + ".tmp", "w") as f:
        json.dump(manifest, f, indent=2, sort_keys=True)
        f.write("\n")
    os.replace(manifest_path + ".tmp", manifest_path)
    write_markdown(os.path.join(out_dir, "MANIFEST.md"), manifest)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("names", nargs="*", help="scenes to regenerate (default: all)")
    ap.add_argument("--bdptref", default=os.path.join(ROOT, "build", "bdptref"))
    ap.add_argument("--out", default=HERE)
    ap.add_argument("--spp-scale", type=float, default=1.0)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--checks-only", action="store_true",
                    help="render nothing: update the entries' check settings from SCENES and rewrite the manifests")
    args = ap.parse_args()
    if args.list:
        print("\n".join(SCENES))
        return 0
    names = args.names or list(SCENES)
    unknown = [n for n in names if n not in SCENES]
    if unknown:
        print("generate.py: unknown scene(s) %s; known: %s" % (", ".join(unknown), ", ".join(SCENES)), file=sys.stderr)
        return 2
    os.makedirs(args.out, exist_ok=True)
    manifest_path = os.path.join(args.out, "MANIFEST.json")
    manifest = {"width": WIDTH, "height": HEIGHT, "references": {}}
    if os.path.exists(manifest_path):
        with open(manifest_path) as f:
            manifest = json.load(f)
    if args.checks_only:
        for name in names:
            if name in manifest["references"]:
                manifest["references"][name]["check"] = dict(SCENES[name]["check"], seed=CHECK_SEED)
        save(args.out, manifest)
        return 0
    # Entries that share another's image are written after it.
    names.sort(key=lambda n: "reference" in SCENES[n])
    for name in names:
        entry = SCENES[name]
        check = dict(entry["check"], seed=CHECK_SEED)
        if "reference" in entry:
            base = manifest["references"].get(entry["reference"])
            if base is None:
                print("generate.py: %s uses %s's image: generate that first" % (name, entry["reference"]), file=sys.stderr)
                return 2
            record = dict(base, scene=entry["scene"], check=check, sharedWith=entry["reference"])
            manifest["references"][name] = record
            save(args.out, manifest)
            continue
        spp = max(2, int(round(entry["spp"] * args.spp_scale)))
        with tempfile.TemporaryDirectory() as tmp:
            stats_path = os.path.join(tmp, "stats.json")
            cmd = render_command(args.bdptref, name, entry, spp, args.threads, args.out) + ["--stats", stats_path]
            print("generate.py: %s: %s" % (name, " ".join(shlex.quote(c) for c in cmd)), file=sys.stderr, flush=True)
            subprocess.run(cmd, check=True)
            with open(stats_path) as f:
                stats = json.load(f)
        shown = ["bdptref"] + [os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd[1:-2]]
        manifest["references"][name] = {
            "scene": entry["scene"], "options": entry["options"], "reference": name + ".exr",
            "integrator": entry["integrator"], "mis": entry.get("mis", ""), "spp": stats["spp"],
            "seed": REFERENCE_SEED, "renderSeconds": stats["renderSeconds"], "threads": stats["threads"],
            "medianRelativeStandardError": stats["medianRelativeStandardError"],
            "p95RelativeStandardError": stats["p95RelativeStandardError"],
            "imageRelativeStandardError": stats["imageRelativeStandardError"],
            "command": " ".join(shlex.quote(c) for c in shown), "check": check,
        }
        save(args.out, manifest)
    return 0


if __name__ == "__main__":
    sys.exit(main())
