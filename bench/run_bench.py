#!/usr/bin/env python3
"""Speed against error: the bdptref benchmark (documented in bench/README.md).

For every scene x estimator it renders a geometric series of sample counts, measures relMSE and
RMSE against a converged reference of the scene (`bdptref compare --json`), and records the
render's own figures (`bdptref render --stats`: seconds, samples/s, extension and shadow rays/s).
In the same run it measures the Embree ceiling of each scene (bench/embree_ceiling with the
same ray counts), 1 -> 2 thread scaling, and how time grows with image size and triangle count.

Writes into --out: results.csv (every render), summary.md (the tables), error-vs-time.svg (log-log
plot per scene), and raw/ (EXRs, stats JSON, references). Standard library only.
"""

import argparse
import csv
import importlib.util
import json
import math
import os
import statistics
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SCENES = {  # name -> file (relative to the repository)
    "cornell-box": "scenes/cornell-box.gltf",
    "veach-mis": "scenes/veach-mis.gltf",
    "narrow-gap": "scenes/narrow-gap.gltf",
    "caustic-glass": "scenes/caustic-glass.gltf",
    "sphere-grid": "scenes/sphere-grid.glb",
}

BASE_ESTIMATORS = [
    ("pt", ["--integrator", "path"]),
    ("lt", ["--integrator", "lt"]),
    ("bdpt-balance", ["--integrator", "bdpt", "--mis", "balance"]),
    ("bdpt-power", ["--integrator", "bdpt", "--mis", "power"]),
]
WAVEFRONT = ("bdpt-wavefront", ["--integrator", "bdpt", "--mode", "wavefront"])

COLOURS = {"pt": "#1f77b4", "lt": "#ff7f0e", "bdpt-balance": "#2ca02c", "bdpt-power": "#d62728",
           "bdpt-wavefront": "#9467bd"}

CSV_COLUMNS = ["scene", "estimator", "spp", "width", "height", "threads", "seconds", "relmse", "rmse",
               "samples_per_s", "extension_rays", "shadow_rays", "rays_per_s", "extension_rays_per_s",
               "shadow_rays_per_s"]


def log(msg):
    print("[bench] " + msg, file=sys.stderr, flush=True)


def run(cmd, ok=(0,)):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode not in ok:
        raise SystemExit("bench: command failed (%d): %s\n%s" % (r.returncode, " ".join(cmd), r.stderr[-2000:]))
    return r.stdout


def estimators(bdptref):
    """The four megakernel estimators, plus the wavefront mode when `render --help` lists --mode."""
    help_text = run([bdptref, "render", "--help"])
    out = list(BASE_ESTIMATORS)
    if "--mode" in help_text:
        out.append(WAVEFRONT)
    return out


def render(a, scene_file, est_args, spp, out_exr, seed, threads=None, size=None):
    stats = out_exr[:-4] + ".json"
    w = size or a.size
    cmd = [a.bdptref, "render", scene_file, "-o", out_exr, "--no-preview", "-q", "--width", str(w),
           "--height", str(w), "--spp", str(spp), "--seed", str(seed), "--max-depth", str(a.max_depth),
           "--threads", str(a.threads if threads is None else threads), "--stats", stats] + est_args
    run(cmd)
    with open(stats) as f:
        return json.load(f)


def compare(a, test_exr, ref_exr):
    # --metrics-only: the error metrics are what the bench wants, not a verdict (exit 0 whenever
    # they were computed). Anything unparsable is a failure.
    out = run([a.bdptref, "compare", "--metrics-only", "--json", test_exr, ref_exr])
    try:
        m = json.loads(out)["metrics"]["overall"]
    except (ValueError, KeyError):
        raise SystemExit("bench: compare gave no metrics for %s against %s" % (test_exr, ref_exr))
    return m["relMse"], m["rmse"]


def ceiling(a, scene_file, ext, shadow, threads, size=None):
    w = size or a.size
    cmd = [a.ceiling, scene_file, "--width", str(w), "--height", str(w), "--extension", str(ext),
           "--shadow", str(shadow), "--threads", str(threads), "--pool", str(a.pool), "--repeats", str(a.repeats)]
    return json.loads(run(cmd))


def median(xs):
    return statistics.median(xs)


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if x == 0:
        return "0"
    if abs(x) >= 1e5 or abs(x) < 1e-3:
        return "%.*e" % (digits - 1, x)
    return "%.*g" % (digits, x)


def spp_series(max_spp):
    s, out = 1, []
    while s <= max_spp:
        out.append(s)
        s *= 2
    return out


def machine_description():
    try:
        text = subprocess.run(["lscpu"], stdout=subprocess.PIPE, text=True).stdout
    except OSError:
        return "lscpu not available"
    keep = ("Model name", "CPU(s)", "Thread(s) per core", "Core(s) per socket", "L2 cache", "L3 cache",
            "Hypervisor vendor")
    lines = [l.strip() for l in text.splitlines() if l.split(":")[0].strip() in keep]
    return "; ".join(" ".join(l.split()) for l in lines)


# ------------------------------------------------------------------------------------------
# the plot

def write_svg(path, rows, scenes, est_names):
    panel_w, panel_h, margin = 330, 260, 55
    cols = min(3, len(scenes))
    nrows = (len(scenes) + cols - 1) // cols
    W, H = cols * panel_w, nrows * panel_h + 40
    svg = ET.Element("svg", xmlns="http://www.w3.org/2000/svg", width=str(W), height=str(H),
                     viewBox="0 0 %d %d" % (W, H), style="font-family:sans-serif;font-size:10px")
    ET.SubElement(svg, "rect", x="0", y="0", width=str(W), height=str(H), fill="white")
    for k, name in enumerate(est_names):  # legend
        x = 10 + k * 120
        ET.SubElement(svg, "line", x1=str(x), y1="15", x2=str(x + 20), y2="15", stroke=COLOURS.get(name, "black"),
                      **{"stroke-width": "2"})
        ET.SubElement(svg, "text", x=str(x + 25), y="19").text = name
    for i, scene in enumerate(scenes):
        ox, oy = (i % cols) * panel_w, 30 + (i // cols) * panel_h
        pts = [r for r in rows if r["scene"] == scene and r["relmse"] > 0 and r["seconds"] > 0]
        if not pts:
            continue
        lx = [math.log10(r["seconds"]) for r in pts]
        ly = [math.log10(r["relmse"]) for r in pts]
        x0, x1 = math.floor(min(lx)), math.ceil(max(lx))
        y0, y1 = math.floor(min(ly)), math.ceil(max(ly))
        x1, y1 = max(x1, x0 + 1), max(y1, y0 + 1)
        pw, ph = panel_w - margin - 10, panel_h - margin - 10

        def X(v):
            return ox + margin + (v - x0) / (x1 - x0) * pw

        def Y(v):
            return oy + 10 + (y1 - v) / (y1 - y0) * ph

        ET.SubElement(svg, "rect", x=str(ox + margin), y=str(oy + 10), width=str(pw), height=str(ph),
                      fill="none", stroke="#888")
        for d in range(x0, x1 + 1):
            ET.SubElement(svg, "line", x1="%.1f" % X(d), y1=str(oy + 10), x2="%.1f" % X(d), y2=str(oy + 10 + ph),
                          stroke="#ddd")
            ET.SubElement(svg, "text", x="%.1f" % (X(d) - 8), y=str(oy + 22 + ph)).text = "1e%d" % d
        for d in range(y0, y1 + 1):
            ET.SubElement(svg, "line", x1=str(ox + margin), y1="%.1f" % Y(d), x2=str(ox + margin + pw),
                          y2="%.1f" % Y(d), stroke="#ddd")
            ET.SubElement(svg, "text", x=str(ox + 18), y="%.1f" % (Y(d) + 3)).text = "1e%d" % d
        ET.SubElement(svg, "text", x=str(ox + margin + pw / 2 - 50), y=str(oy + 36 + ph)).text = \
            "%s: render seconds" % scene
        ET.SubElement(svg, "text", x=str(ox + 2), y=str(oy + 8)).text = "relMSE"
        for name in est_names:
            mine = sorted((r for r in pts if r["estimator"] == name), key=lambda r: r["seconds"])
            if not mine:
                continue
            coords = " ".join("%.1f,%.1f" % (X(math.log10(r["seconds"])), Y(math.log10(r["relmse"]))) for r in mine)
            ET.SubElement(svg, "polyline", points=coords, fill="none", stroke=COLOURS.get(name, "black"),
                          **{"stroke-width": "1.5"})
            for r in mine:
                ET.SubElement(svg, "circle", cx="%.1f" % X(math.log10(r["seconds"])),
                              cy="%.1f" % Y(math.log10(r["relmse"])), r="2", fill=COLOURS.get(name, "black"))
    ET.ElementTree(svg).write(path, encoding="utf-8", xml_declaration=True)


# ------------------------------------------------------------------------------------------

def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bdptref", default=os.path.join(ROOT, "build", "bdptref"), help="the bdptref executable")
    p.add_argument("--ceiling", default=os.path.join(ROOT, "build", "bench", "embree_ceiling"),
                   help="the embree_ceiling executable")
    p.add_argument("--out", default=os.path.join(ROOT, "bench", "out"), help="output folder")
    p.add_argument("--scenes", default=",".join(SCENES), help="comma-separated scene names (%(default)s)")
    p.add_argument("--size", type=int, default=64, help="image width = height (default 64)")
    p.add_argument("--max-spp", type=int, default=32, help="largest budget; budgets are 1, 2, 4, ... (default 32)")
    p.add_argument("--ref-spp", type=int, default=512, help="samples per pixel of each reference (default 512)")
    p.add_argument("--max-depth", type=int, default=8, help="--max-depth of every render (default 8)")
    p.add_argument("--threads", type=int, default=0, help="threads of the error renders (default 0 = all)")
    p.add_argument("--repeats", type=int, default=3, help="repeats of each timing for medians (default 3)")
    p.add_argument("--pool", type=int, default=1000000, help="ray pool size of embree_ceiling (default 1e6)")
    p.add_argument("--no-scaling", action="store_true", help="skip the thread/image-size/triangle scaling runs")
    p.add_argument("--quick", action="store_true",
                   help="smoke-test size: 16x16, budgets 1..2 spp, references of 8 spp, cornell-box only, pool 1e4")
    a = p.parse_args()
    if a.quick:
        a.size, a.max_spp, a.ref_spp, a.repeats, a.pool = 16, 2, 8, 1, 10000
        if a.scenes == ",".join(SCENES):
            a.scenes = "cornell-box"
    scenes = [s for s in a.scenes.split(",") if s]
    for s in scenes:
        if s not in SCENES:
            raise SystemExit("bench: unknown scene '%s' (known: %s)" % (s, ", ".join(SCENES)))
    raw = os.path.join(a.out, "raw")
    os.makedirs(raw, exist_ok=True)
    ests = estimators(a.bdptref)
    est_names = [e[0] for e in ests]
    bdpt_args = dict(ests)["bdpt-balance"]
    rows, figures = [], []
    t_start = time.time()

    for scene in scenes:
        sf = os.path.join(ROOT, SCENES[scene])
        ref = os.path.join(raw, "%s-ref-%d-%d-%d.exr" % (scene, a.size, a.ref_spp, a.max_depth))
        if not os.path.exists(ref):
            log("%s: reference (bdpt balance, %d spp)" % (scene, a.ref_spp))
            render(a, sf, bdpt_args, a.ref_spp, ref, seed=1000003)
        last = {}
        for name, args in ests:
            for spp in spp_series(a.max_spp):
                exr = os.path.join(raw, "%s-%s-%d.exr" % (scene, name, spp))
                st = render(a, sf, args, spp, exr, seed=1)
                relmse, rmse = compare(a, exr, ref)
                row = {"scene": scene, "estimator": name, "spp": spp, "width": st["width"], "height": st["height"],
                       "threads": st["threads"], "seconds": st["renderSeconds"], "relmse": relmse, "rmse": rmse,
                       "samples_per_s": st["samplesPerSecond"], "extension_rays": st["extensionRays"],
                       "shadow_rays": st["shadowRays"], "rays_per_s": st["raysPerSecond"],
                       "extension_rays_per_s": st["extensionRaysPerSecond"],
                       "shadow_rays_per_s": st["shadowRaysPerSecond"]}
                rows.append(row)
                last[name] = row
            log("%s %s: relMSE %s at %d spp in %ss" % (scene, name, fmt(last[name]["relmse"]), a.max_spp,
                                                       fmt(last[name]["seconds"])))
        b = last["bdpt-balance"]
        ceil = ceiling(a, sf, b["extension_rays"], b["shadow_rays"], b["threads"])
        for name in est_names:
            r = last[name]
            figures.append({"scene": scene, "estimator": name, "spp": r["spp"], "seconds": r["seconds"],
                            "relmse": r["relmse"], "efficiency": 1.0 / (r["relmse"] * r["seconds"]),
                            "samples_per_s": r["samples_per_s"], "extension_rays_per_s": r["extension_rays_per_s"],
                            "shadow_rays_per_s": r["shadow_rays_per_s"], "rays_per_s": r["rays_per_s"],
                            "ceiling_rays_per_s": ceil["raysPerSecond"],
                            "ceiling_ratio": r["rays_per_s"] / ceil["raysPerSecond"]})

    with open(os.path.join(a.out, "results.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow(r)
    write_svg(os.path.join(a.out, "error-vs-time.svg"), rows, scenes, est_names)

    scaling = None if a.no_scaling else scaling_runs(a, bdpt_args, raw)
    if scaling is not None and WAVEFRONT[0] in est_names:
        scaling["modes"] = mode_runs(a, raw)

    md = []
    md.append("Machine: %s. Image %dx%d, max depth %d, budgets 1..%d spp, references %d spp (bdpt balance, "
              "another seed), threads %s. Timings are render seconds (scene loading excluded); the machine is "
              "shared, so ratios are measured side by side in one run and quoted as medians of %d repeats."
              % (machine_description(), a.size, a.size, a.max_depth, a.max_spp, a.ref_spp,
                 "all" if a.threads == 0 else a.threads, a.repeats))
    md.append("")
    md.append("### Error and efficiency at the largest budget (%d spp)" % a.max_spp)
    md.append("")
    md.append("| scene | estimator | seconds | relMSE | efficiency 1/(relMSE*s) | samples/s | extension rays/s "
              "| shadow rays/s | rays/s | Embree ceiling rays/s | ratio to ceiling |")
    md.append("|---|---|---|---|---|---|---|---|---|---|---|")
    for f_ in figures:
        md.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            f_["scene"], f_["estimator"], fmt(f_["seconds"]), fmt(f_["relmse"]), fmt(f_["efficiency"]),
            fmt(f_["samples_per_s"]), fmt(f_["extension_rays_per_s"]), fmt(f_["shadow_rays_per_s"]),
            fmt(f_["rays_per_s"]), fmt(f_["ceiling_rays_per_s"]), "%.0f%%" % (100 * f_["ceiling_ratio"])))
    if scaling:
        md += scaling_markdown(scaling, est_names)
    md.append("")
    md.append("Total benchmark time %.0f s." % (time.time() - t_start))
    with open(os.path.join(a.out, "summary.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    with open(os.path.join(a.out, "summary.json"), "w") as f:
        json.dump({"figures": figures, "scaling": scaling}, f, indent=1, sort_keys=True)
    check_outputs(a.out, len(rows))
    log("wrote %s/{results.csv,summary.md,summary.json,error-vs-time.svg}" % a.out)


def load_generator():
    spec = importlib.util.spec_from_file_location("bdptref_scene_generator", os.path.join(ROOT, "scenes", "generate.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def scaling_runs(a, bdpt_args, raw):
    """Thread scaling, image-size and triangle-count growth (medians of interleaved repeats)."""
    cornell = os.path.join(ROOT, SCENES["cornell-box"])
    spp = max(1, a.max_spp // 2)
    out = {}
    # 1 -> 2 threads, bdptref (bdpt balance) and the Embree ceiling, interleaved.
    t = {1: [], 2: []}
    for _ in range(a.repeats):
        for n in (1, 2):
            st = render(a, cornell, bdpt_args, spp, os.path.join(raw, "threads-%d.exr" % n), seed=1, threads=n)
            t[n].append(st)
    c = {1: [], 2: []}
    last = t[2][-1]
    for n in (1, 2):
        c[n].append(ceiling(a, cornell, last["extensionRays"], last["shadowRays"], n)["seconds"])
    s1, s2 = median([s["renderSeconds"] for s in t[1]]), median([s["renderSeconds"] for s in t[2]])
    out["threads"] = {"spp": spp, "seconds1": s1, "seconds2": s2, "speedup": s1 / s2,
                      "rays_per_s_2": median([s["raysPerSecond"] for s in t[2]]),
                      "ceiling_seconds1": c[1][0], "ceiling_seconds2": c[2][0], "ceiling_speedup": c[1][0] / c[2][0]}
    out["threads"]["ceiling_ratio_2"] = out["threads"]["rays_per_s_2"] / (
        (last["extensionRays"] + last["shadowRays"]) / c[2][0])
    # Image size.
    sizes = []
    for size in (a.size // 2, a.size, a.size * 2):
        size = max(size, 4)
        secs = [render(a, cornell, bdpt_args, spp, os.path.join(raw, "size-%d.exr" % size), seed=1, size=size)
                ["renderSeconds"] for _ in range(a.repeats)]
        sizes.append({"size": size, "pixels": size * size, "seconds": median(secs),
                      "us_per_sample": 1e6 * median(secs) / (size * size * spp)})
    out["image_size"] = sizes
    # Triangle count: the same sphere grid tessellated at levels 0..4 (path tracer, so the work
    # per sample barely changes while the BVH grows).
    gen = load_generator()
    tris = []
    levels = (0, 1) if a.quick else (0, 1, 2, 3, 4)
    for level in levels:
        path = os.path.join(raw, "sphere-grid-%d.glb" % level)
        if level == gen.SPHERE_GRID_LEVEL:
            path = os.path.join(ROOT, SCENES["sphere-grid"])  # the shipped file is this level
        elif not os.path.exists(path):
            gen.OUT_DIR = raw
            gen.write_glb(gen.sphere_grid(level), os.path.basename(path))
        sts = [render(a, path, ["--integrator", "path"], spp, os.path.join(raw, "tris-%d.exr" % level), seed=1)
               for _ in range(a.repeats)]
        st = sts[-1]
        ceil = ceiling(a, path, st["extensionRays"], st["shadowRays"], st["threads"])
        tris.append({"level": level, "triangles": st["triangles"], "seconds": median([s["renderSeconds"] for s in sts]),
                     "rays_per_s": median([s["raysPerSecond"] for s in sts]), "ceiling_rays_per_s": ceil["raysPerSecond"]})
    out["triangles"] = tris
    return out


def mode_runs(a, raw):
    """Wavefront against megakernel, BDPT balance, 2 threads, interleaved repeats (median)."""
    out = []
    for scene, path in (("cornell-box", SCENES["cornell-box"]), ("mis-zoo", "scenes/mis-zoo.gltf"),
                        ("veach-mis", SCENES["veach-mis"])):
        sf = os.path.join(ROOT, path)
        if not os.path.exists(sf):
            continue
        spp = a.max_spp
        t = {"megakernel": [], "wavefront": []}
        for _ in range(max(a.repeats, 5) if not a.quick else 1):
            for mode in t:
                st = render(a, sf, ["--integrator", "bdpt", "--mode", mode], spp,
                            os.path.join(raw, "mode-%s-%s.exr" % (scene, mode)), seed=1, threads=2)
                t[mode].append(st["renderSeconds"])
        mk, wf = median(t["megakernel"]), median(t["wavefront"])
        out.append({"scene": scene, "spp": spp, "megakernel_seconds": mk, "wavefront_seconds": wf,
                    "wavefront_speed": mk / wf})
    return out


def scaling_markdown(s, est_names):
    md = ["", "### 1 -> 2 threads (cornell-box, bdpt balance, %d spp, median of repeats)" % s["threads"]["spp"], "",
          "| | 1 thread s | 2 threads s | speedup |", "|---|---|---|---|"]
    t = s["threads"]
    md.append("| bdptref | %s | %s | %.2fx |" % (fmt(t["seconds1"]), fmt(t["seconds2"]), t["speedup"]))
    md.append("| Embree ceiling (same rays) | %s | %s | %.2fx |" % (fmt(t["ceiling_seconds1"]), fmt(t["ceiling_seconds2"]),
                                                               t["ceiling_speedup"]))
    if s.get("modes"):
        md += ["", "### Wavefront against megakernel (bdpt balance, 2 threads, median of interleaved repeats)", "",
               "| scene | spp | megakernel s | wavefront s | wavefront speed (megakernel s / wavefront s) |",
               "|---|---|---|---|---|"]
        for r in s["modes"]:
            md.append("| %s | %d | %s | %s | %.2fx |" % (r["scene"], r["spp"], fmt(r["megakernel_seconds"]),
                                                       fmt(r["wavefront_seconds"]), r["wavefront_speed"]))
    md += ["", "### Image size (cornell-box, bdpt balance)", "", "| size | pixels | seconds | us per sample |",
           "|---|---|---|---|"]
    for r in s["image_size"]:
        md.append("| %dx%d | %d | %s | %s |" % (r["size"], r["size"], r["pixels"], fmt(r["seconds"]), fmt(r["us_per_sample"])))
    md += ["", "### Triangle count (sphere grid, same layout tessellated finer; path tracer)", "",
           "| icosphere level | triangles | seconds | rays/s | Embree ceiling rays/s | ratio |", "|---|---|---|---|---|---|"]
    for r in s["triangles"]:
        md.append("| %d | %d | %s | %s | %s | %.0f%% |" % (r["level"], r["triangles"], fmt(r["seconds"]), fmt(r["rays_per_s"]),
                                                       fmt(r["ceiling_rays_per_s"]), 100 * r["rays_per_s"] / r["ceiling_rays_per_s"]))
    return md


def check_outputs(out, n_rows):
    """Well-formedness of what was written (the CTest smoke test relies on this)."""
    with open(os.path.join(out, "results.csv")) as f:
        rows = list(csv.DictReader(f))
    if len(rows) != n_rows or n_rows == 0:
        raise SystemExit("bench: results.csv has %d rows, expected %d" % (len(rows), n_rows))
    for r in rows:
        for k in CSV_COLUMNS[2:]:
            v = float(r[k])
            if not math.isfinite(v) or v < 0:
                raise SystemExit("bench: results.csv: %s = %s is not a finite non-negative number" % (k, r[k]))
        if float(r["seconds"]) <= 0 or float(r["relmse"]) <= 0 or float(r["samples_per_s"]) <= 0:
            raise SystemExit("bench: results.csv: zero time, error or speed in %s" % r)
    root = ET.parse(os.path.join(out, "error-vs-time.svg")).getroot()
    if not root.tag.endswith("svg") or not any(e.tag.endswith("polyline") for e in root.iter()):
        raise SystemExit("bench: error-vs-time.svg has no curves")
    with open(os.path.join(out, "summary.md")) as f:
        if "| scene | estimator |" not in f.read():
            raise SystemExit("bench: summary.md has no table")


if __name__ == "__main__":
    main()
