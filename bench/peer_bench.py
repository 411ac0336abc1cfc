#!/usr/bin/env python3
"""bdptref against its peer, SmallVCM, on the peer's own scene (documented in bench/README.md).

    bench/peer_bench.py --peer PEER_DIR [--size 128] [--spp 4,16,64] [--repeats 5] [--threads 1,2]

PEER_DIR is a SmallVCM checkout prepared for this comparison: build.sh (builds the peer), scene4.gltf
(its scene 4 for bdptref) and a peer binary that understands -r, -n, -l, --seed and .pfm output (the
folder the project's maintainers were given holds exactly that; the peer is never part of the project).

For each estimator pair (bdptref path/lt/bdpt against the peer's pt/lt/bpt), thread count and sample
count, it renders both renderers interleaved (peer, bdptref, peer, bdptref, ... with seeds 1..R),
measures each process's CPU-seconds (user + system, from wait4) and wall time, and computes relMSE
against ONE common converged reference (a bdptref BDPT render at --ref-spp, cached in --out). Then

    efficiency = 1 / (relMSE x CPU-seconds)        (medians over the repeats)

and the ratio bdptref / peer. "Per process" is the smallest sample count (start-up counts); "at many
samples" is the largest. It also reports bdptref's rays/s against the Embree ceiling of the scene
(bench/embree_ceiling with the same ray counts). Writes peer.csv and peer.md into --out.
Standard library only.
"""

import argparse
import csv
import json
import math
import os
import resource
import statistics
import struct
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# bdptref integrator, peer algorithm
# estimator -> (bdptref --integrator, the peer's -a, extra bdptref arguments)
PAIRS = {"pt": ("path", "pt", []), "lt": ("lt", "lt", []), "bdpt": ("bdpt", "bpt", []),
         "bdpt-wavefront": ("bdpt", "bpt", ["--mode", "wavefront"])}
EPSILON = 0.01  # relMSE = mean((t - r)^2 / (r^2 + epsilon)), as bdptref compare's default


def log(msg):
    print("[peer-bench] " + msg, file=sys.stderr, flush=True)


def run_measured(cmd):
    """Runs cmd; returns (wall seconds, CPU seconds of the process and all its threads, stdout)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        raise SystemExit("peer-bench: command failed (%d): %s\n%s" % (r.returncode, " ".join(cmd),
                                                                      r.stderr.decode(errors="replace")[-2000:]))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, r.stdout


def read_pfm(path, top_row_first):
    """(width, height, r g b floats row by row, top row first) of a colour PFM."""
    with open(path, "rb") as f:
        data = f.read()
    tokens, pos = [], 0
    while len(tokens) < 4:  # "PF" width height scale
        while data[pos:pos + 1].isspace():
            pos += 1
        start = pos
        while not data[pos:pos + 1].isspace():
            pos += 1
        tokens.append(data[start:pos])
    pos += 1  # exactly one whitespace character before the raster
    if tokens[0] != b"PF":
        raise SystemExit("peer-bench: %s is not a colour PFM" % path)
    w, h, scale = int(tokens[1]), int(tokens[2]), float(tokens[3])
    values = struct.unpack_from(("<" if scale < 0 else ">") + "%df" % (w * h * 3), data, pos)
    rows = [values[y * w * 3:(y + 1) * w * 3] for y in range(h)]
    if not top_row_first:  # standard PFM stores the bottom row first
        rows.reverse()
    return w, h, [v for row in rows for v in row]


def write_exr(path, w, h, rgb):
    """An uncompressed single-part scanline EXR with float R, G, B (rgb: top row first)."""
    def attr(name, typ, payload):
        return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(payload)) + payload

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    header = (struct.pack("<ii", 20000630, 2) + attr("channels", "chlist", chlist) +
              attr("compression", "compression", b"\0") +
              attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1)) +
              attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1)) +
              attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)) +
              attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)) +
              attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    line_bytes = 8 + 3 * 4 * w
    first = len(header) + 8 * h
    out = [header, struct.pack("<%dQ" % h, *[first + y * line_bytes for y in range(h)])]
    for y in range(h):
        row = rgb[y * w * 3:(y + 1) * w * 3]
        out.append(struct.pack("<ii", y, 3 * 4 * w))
        for c in (2, 1, 0):  # channels in alphabetical order: B, G, R
            out.append(struct.pack("<%df" % w, *row[c::3]))
    with open(path, "wb") as f:
        f.write(b"".join(out))


def relmse(a, test_exr, ref_exr):
    """relMSE from bdptref compare --metrics-only --json (no verdict asked: a plain RGB test image is fine)."""
    r = subprocess.run([a.bdptref, "compare", "--metrics-only", "--json", test_exr, ref_exr], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True)
    try:
        m = json.loads(r.stdout)["metrics"]["overall"]
    except (ValueError, KeyError):
        raise SystemExit("peer-bench: compare gave no metrics for %s (exit %d): %s" % (test_exr, r.returncode, r.stderr[-500:]))
    return m["relMse"]


def median(xs):
    return statistics.median(xs)


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if abs(x) >= 1e5 or (x != 0 and abs(x) < 1e-3):
        return "%.*e" % (digits - 1, x)
    return "%.*g" % (digits, x)


def bdptref_cmd(a, integrator, spp, seed, threads, out_exr, stats=None, extra=()):
    cmd = [a.bdptref, "render", a.scene, "--width", str(a.size), "--height", str(a.size), "--spp", str(spp),
           "--seed", str(seed), "--max-depth", str(a.segments - 1), "--threads", str(threads), "--integrator", integrator,
           "-q", "--no-preview", "-o", out_exr] + list(extra)
    return cmd + (["--stats", stats] if stats else [])


def peer_cmd(a, algorithm, spp, seed, threads, out_pfm):
    return [a.peer_exe, "-s", "4", "-a", algorithm, "-r", str(a.size), "-n", str(threads), "-l", str(a.segments),
            "-i", str(spp), "--seed", str(seed), "-o", out_pfm]


def reference(a):
    ref = os.path.join(a.out, "reference-%d-%dspp-%dseg.exr" % (a.size, a.ref_spp, a.segments))
    if not os.path.exists(ref):
        log("rendering the common reference (bdptref BDPT, %d spp; cached as %s)" % (a.ref_spp, ref))
        run_measured(bdptref_cmd(a, "bdpt", a.ref_spp, 1000, 0, ref + ".tmp.exr"))
        os.replace(ref + ".tmp.exr", ref)
    return ref


def measure(a, ref, est, threads, spp, rows):
    ours, theirs, extra = PAIRS[est]
    raw = os.path.join(a.out, "raw")
    for seed in range(1, a.repeats + 1):  # interleaved: the machine's load hits both alike
        tag = "%s-t%d-s%d-seed%d" % (est, threads, spp, seed)
        pfm = os.path.join(raw, "peer-" + tag + ".pfm")
        wall, cpu, _ = run_measured(peer_cmd(a, theirs, spp, seed, threads, pfm))
        w, h, rgb = read_pfm(pfm, top_row_first=True)  # the peer writes its top row first
        write_exr(pfm[:-4] + ".exr", w, h, rgb)
        rows.append(dict(renderer="smallvcm", estimator=est, threads=threads, spp=spp, seed=seed, wall=wall, cpu=cpu,
                         relmse=relmse(a, pfm[:-4] + ".exr", ref), rays_per_s=""))
        exr = os.path.join(raw, "bdptref-" + tag + ".exr")
        stats = exr[:-4] + ".json"
        wall, cpu, _ = run_measured(bdptref_cmd(a, ours, spp, seed, threads, exr, stats, extra))
        with open(stats) as f:
            st = json.load(f)
        rows.append(dict(renderer="bdptref", estimator=est, threads=threads, spp=spp, seed=seed, wall=wall, cpu=cpu,
                         relmse=relmse(a, exr, ref), rays_per_s=st.get("raysPerSecond", ""),
                         extension_rays=st.get("extensionRays", 0), shadow_rays=st.get("shadowRays", 0)))


def summarise(a, rows):
    """Medians per (estimator, threads, spp, renderer) and the bdptref / peer ratios."""
    lines = ["| estimator | threads | spp | SmallVCM CPU-s (wall) | bdptref CPU-s (wall) | SmallVCM relMSE | bdptref relMSE "
             "| efficiency ratio bdptref/SmallVCM | time-per-sample ratio |",
             "|---|---|---|---|---|---|---|---|---|"]
    ratios = {}
    for est in a.estimator_list:
        for threads in a.thread_list:
            for spp in a.spp_list:
                m = {}
                for who in ("smallvcm", "bdptref"):
                    sel = [r for r in rows if r["renderer"] == who and r["estimator"] == est and r["threads"] == threads
                           and r["spp"] == spp]
                    m[who] = dict(cpu=median([r["cpu"] for r in sel]), wall=median([r["wall"] for r in sel]),
                                  relmse=median([r["relmse"] for r in sel]))
                    m[who]["eff"] = 1.0 / (m[who]["relmse"] * m[who]["cpu"])
                ratio = m["bdptref"]["eff"] / m["smallvcm"]["eff"]
                ratios[(est, threads, spp)] = ratio
                lines.append("| %s | %d | %d | %s (%s) | %s (%s) | %s | %s | **%s** | %s |" % (
                    est, threads, spp, fmt(m["smallvcm"]["cpu"]), fmt(m["smallvcm"]["wall"]), fmt(m["bdptref"]["cpu"]),
                    fmt(m["bdptref"]["wall"]), fmt(m["smallvcm"]["relmse"]), fmt(m["bdptref"]["relmse"]), fmt(ratio),
                    fmt(m["bdptref"]["cpu"] / m["smallvcm"]["cpu"])))
    return lines, ratios


def wavefront_lines(a, rows):
    """bdptref's wavefront mode against its megakernel (both BDPT balance), medians of the same run."""
    if "bdpt" not in a.estimator_list or "bdpt-wavefront" not in a.estimator_list:
        return []
    lines = ["", "## Wavefront mode against the megakernel (bdptref BDPT, same run)", "",
             "| threads | spp | megakernel CPU-s (wall) | wavefront CPU-s (wall) | wavefront / megakernel CPU-s | wall |",
             "|---|---|---|---|---|---|"]
    for threads in a.thread_list:
        for spp in a.spp_list:
            m = {}
            for est in ("bdpt", "bdpt-wavefront"):
                sel = [r for r in rows if r["renderer"] == "bdptref" and r["estimator"] == est and r["threads"] == threads
                       and r["spp"] == spp]
                m[est] = (median([r["cpu"] for r in sel]), median([r["wall"] for r in sel]))
            (mc, mw), (wc, ww) = m["bdpt"], m["bdpt-wavefront"]
            lines.append("| %d | %d | %s (%s) | %s (%s) | **%s** | %s |" % (
                threads, spp, fmt(mc), fmt(mw), fmt(wc), fmt(ww), fmt(wc / mc), fmt(ww / mw)))
    return lines


def ceiling_lines(a, rows):
    """bdptref's BDPT rays/s against bench/embree_ceiling tracing the same numbers of rays."""
    if not os.path.exists(a.ceiling):
        return ["(bench/embree_ceiling not built: `cmake --build build --target embree_ceiling`)"]
    lines = ["| threads | bdptref BDPT rays/s | Embree ceiling rays/s | fraction |", "|---|---|---|---|"]
    spp = max(a.spp_list)
    for threads in a.thread_list:
        sel = [r for r in rows if r["renderer"] == "bdptref" and r["estimator"] == "bdpt" and r["threads"] == threads
               and r["spp"] == spp]
        if not sel:
            continue
        ours = median([r["rays_per_s"] for r in sel])
        ext, shadow = sel[0]["extension_rays"], sel[0]["shadow_rays"]
        out = subprocess.run([a.ceiling, a.scene, "--width", str(a.size), "--height", str(a.size), "--extension", str(ext),
                              "--shadow", str(shadow), "--threads", str(threads), "--repeats", str(a.repeats)],
                             stdout=subprocess.PIPE, text=True, check=True).stdout
        ceil = json.loads(out)["raysPerSecond"]
        lines.append("| %d | %s | %s | %s |" % (threads, fmt(ours), fmt(ceil), fmt(ours / ceil)))
    return lines


def run_bench(a):
    a.estimator_list = [e for e in a.estimators.split(",") if e]
    a.spp_list = [int(s) for s in a.spp.split(",")]
    a.thread_list = [int(t) for t in a.threads.split(",")]
    for e in a.estimator_list:
        if e not in PAIRS:
            raise SystemExit("peer-bench: unknown estimator %r (choose from %s)" % (e, ",".join(PAIRS)))
    a.scene = os.path.join(a.peer, "scene4.gltf")
    for need in (os.path.join(a.peer, "build.sh"), a.scene, a.bdptref):
        if not os.path.exists(need):
            raise SystemExit("peer-bench: %s does not exist" % need)
    os.makedirs(os.path.join(a.out, "raw"), exist_ok=True)
    build = os.path.join(a.out, "peer-build")
    a.peer_exe = subprocess.run(["bash", os.path.join(a.peer, "build.sh"), build], stdout=subprocess.PIPE, text=True,
                                check=True).stdout.strip().splitlines()[-1]
    ref = reference(a)
    rows = []
    for est in a.estimator_list:
        for threads in a.thread_list:
            for spp in a.spp_list:
                log("%s, %d thread(s), %d spp, %d interleaved runs each" % (est, threads, spp, a.repeats))
                measure(a, ref, est, threads, spp, rows)
    with open(os.path.join(a.out, "peer.csv"), "w", newline="") as f:
        cols = ["renderer", "estimator", "threads", "spp", "seed", "wall", "cpu", "relmse", "rays_per_s"]
        wr = csv.DictWriter(f, fieldnames=cols, extrasaction="ignore")
        wr.writeheader()
        wr.writerows(rows)
    table, _ = summarise(a, rows)
    md = ["# bdptref against SmallVCM (scene 4, %d x %d, %d segments = bdptref --max-depth %d)" % (
              a.size, a.size, a.segments, a.segments - 1), "",
          "Medians of %d interleaved runs (seeds 1..%d); relMSE against one bdptref BDPT reference at %d spp; "
          "efficiency = 1 / (relMSE x CPU-seconds of the whole process)." % (a.repeats, a.repeats, a.ref_spp), ""]
    md += table + ["", "## BDPT rays per second against the Embree ceiling (largest spp)", ""] + ceiling_lines(a, rows)
    md += wavefront_lines(a, rows)
    with open(os.path.join(a.out, "peer.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))
    return 0


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--peer", required=True, help="the SmallVCM peer folder (build.sh, scene4.gltf)")
    p.add_argument("--bdptref", default=os.path.join(ROOT, "build", "bdptref"))
    p.add_argument("--ceiling", default=os.path.join(ROOT, "build", "bench", "embree_ceiling"))
    p.add_argument("--out", default=os.path.join(ROOT, "bench", "out-peer"))
    p.add_argument("--size", type=int, default=128, help="image width = height (default 128)")
    p.add_argument("--segments", type=int, default=10, help="peer path length in segments; bdptref --max-depth is one less")
    p.add_argument("--spp", default="4,16,64", help="sample counts (default 4,16,64)")
    p.add_argument("--threads", default="1,2", help="thread counts (default 1,2)")
    p.add_argument("--repeats", type=int, default=5, help="interleaved runs per setting, seeds 1..R (default 5)")
    p.add_argument("--estimators", default="bdpt,bdpt-wavefront,pt,lt",
                   help="subset of bdpt,bdpt-wavefront,pt,lt (bdpt-wavefront: bdptref --mode wavefront against the "
                        "peer's bpt; with bdpt, a wavefront / megakernel table)")
    p.add_argument("--ref-spp", type=int, default=4096, help="spp of the common reference (bdptref BDPT)")
    a = p.parse_args()
    raise SystemExit(run_bench(a))


if __name__ == "__main__":
    main()
