#!/usr/bin/python3
"""Light tree against power sampling: relMSE x CPU-seconds (bench/README.md, "Many lights: the light tree").

    python3 bench/light_tree_bench.py [--bdptref build/bdptref] [--integrator path|bdpt] [--size 64] [--spp 16]
                                      [--ref-spp 2048] [--repeats 3] [--threads 1] [--ref-threads 2]
                                      [--out /tmp/light-tree-bench] [--only many-lights,...]

For each scene (the two of bench/make_many_lights.py, generated into --out, and shipped scenes): a
reference render (path tracer, the tree, --ref-spp, seed 1), then --repeats renders of --spp with
--integrator (path by default; bdpt: its s = 1 strategy chooses with the tree) and each sampler (seeds 2, 3, ...; power and tree interleaved), relMSE of each against the reference
(`compare --metrics-only`, epsilon 0.01), CPU-seconds = the user + system CPU time of the render
process (loading and the tree's build included; CPU time, not wall time, because the machine may be
shared). The figure of
merit is mean relMSE x mean CPU-seconds (lower is better); "gain" = power's / tree's (> 1: the
tree wins). Every estimator and sampler here is unbiased (tests/scenes/test_light_tree_render.cpp,
test_light_tree_bdpt.cpp), so the reference's estimator does not matter beyond its noise, which adds the same to both.
"""
import argparse
import json
import os
import resource
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SHIPPED = [  # name, file, extra arguments
    ("cornell-box", "scenes/cornell-box.gltf", []),
    ("mis-zoo + env", "scenes/mis-zoo.gltf", ["--env", "0.3,0.35,0.4"]),
    ("gltf-features", "scenes/gltf-features.gltf", []),
    ("cornell-small-light", "scenes/cornell-small-light.gltf", []),
]


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("bench: %s failed (%d): %s" % (" ".join(cmd), r.returncode, r.stderr.strip()))
    return r.stdout


def cpu_seconds_of(cmd):
    """Runs cmd; returns the user + system CPU-seconds it used (loading and the tree's build included)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    run(cmd)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def render(a, scene, extra, integrator, sampler, spp, seed, out, threads):
    return cpu_seconds_of([a.bdptref, "render", scene, "-o", out, "--no-preview", "-q", "--width", str(a.size), "--height",
                           str(a.size), "--spp", str(spp), "--seed", str(seed), "--max-depth", str(a.max_depth),
                           "--threads", str(threads), "--integrator", integrator, "--light-sampler", sampler] + extra)


def rel_mse(a, test, ref):
    out = run([a.bdptref, "compare", "--metrics-only", "--json", test, ref])
    return json.loads(out)["metrics"]["overall"]["relMse"]


def bench_scene(a, name, scene, extra):
    tag = name.replace(" ", "").replace("+", "-")
    ref = os.path.join(a.out, tag + "-ref.exr")
    render(a, scene, extra, "path", "tree", a.ref_spp, 1, ref, a.ref_threads)
    res = {"power": [], "tree": []}
    for rep in range(a.repeats):
        for sampler in ("power", "tree"):
            out = os.path.join(a.out, "%s-%s-%d.exr" % (tag, sampler, rep))
            secs = render(a, scene, extra, a.integrator, sampler, a.spp, 2 + rep, out, a.threads)
            res[sampler].append((rel_mse(a, out, ref), secs))
    row = {"scene": name}
    for sampler, runs in res.items():
        mse = sum(r for r, _ in runs) / len(runs)
        secs = sum(s for _, s in runs) / len(runs)
        row[sampler] = (mse, secs, mse * secs)
    row["gain"] = row["power"][2] / row["tree"][2]
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bdptref", default=os.path.join(ROOT, "build", "bdptref"))
    ap.add_argument("--integrator", default="path", choices=["path", "bdpt"],
                    help="the estimator timed (the reference is always the path tracer with the tree)")
    ap.add_argument("--out", default="/tmp/light-tree-bench")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--ref-threads", type=int, default=2)
    ap.add_argument("--max-depth", type=int, default=5)
    ap.add_argument("--lights", type=int, default=4000)
    ap.add_argument("--room", type=float, default=15.0, help="make_many_lights.py --room (default 15: a 30 x 30 m hall)")
    ap.add_argument("--only", default="", help="comma-separated scene names (default: all)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    run([sys.executable, os.path.join(ROOT, "bench", "make_many_lights.py"), "--out", a.out, "--lights", str(a.lights),
         "--room", str(a.room)])
    scenes = [("many-lights", os.path.join(a.out, "many-lights.gltf"), []),
              ("emissive-texture", os.path.join(a.out, "emissive-texture.gltf"), [])]
    scenes += [(n, os.path.join(ROOT, f), e) for n, f, e in SHIPPED]
    if a.only:
        keep = a.only.split(",")
        scenes = [s for s in scenes if s[0] in keep]
    print("| scene | power relMSE | power CPU-s | tree relMSE | tree CPU-s | gain (power / tree relMSE x CPU-s) |")
    print("|---|---|---|---|---|---|")
    for name, scene, extra in scenes:
        r = bench_scene(a, name, scene, extra)
        print("| %s | %.4g | %.3g | %.4g | %.3g | **%.2fx** |" % (name, r["power"][0], r["power"][1], r["tree"][0],
                                                                r["tree"][1], r["gain"]), flush=True)


if __name__ == "__main__":
    main()
