#!/usr/bin/python3
"""Start-up cost of the bdptref CLI: CPU-seconds (user + sys of the child, from wait4) and wall
time of short commands, median of N runs each, interleaved so machine noise hits all alike.

    bench/startup.py [--binary build/bdptref] [--runs 15]

Prints a Markdown table (bench/README.md, "Start-up"). The inputs (two 8x8 renders, a path JSON)
are made first in a temporary folder and are not timed. Not a test: nothing is asserted.
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "scenes", "cornell-box.gltf")


def run_once(cmd, ok_codes=(0,)):
    t0 = time.perf_counter()
    with open(os.devnull, "wb") as null:
        p = subprocess.Popen(cmd, stdout=null, stderr=null)
        _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    code = os.waitstatus_to_exitcode(status)
    if code not in ok_codes:
        sys.exit("startup.py: %s exited %d" % (" ".join(cmd), code))
    return ru.ru_utime + ru.ru_stime, wall


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "bdptref"))
    ap.add_argument("--runs", type=int, default=15)
    a = ap.parse_args()
    b = os.path.abspath(a.binary)
    tmp = tempfile.mkdtemp(prefix="bdptref-startup-")
    A, B, M = (os.path.join(tmp, n) for n in ("a.exr", "b.exr", "m.exr"))
    tiny = [b, "render", SCENE, "--width", "8", "--height", "8", "--threads", "1"]
    subprocess.run(tiny + ["-o", A, "--sample-range", "0:2"], check=True, capture_output=True)
    subprocess.run(tiny + ["-o", B, "--sample-range", "2:4"], check=True, capture_output=True)
    path_json = os.path.join(tmp, "path.json")
    subprocess.run([b, "trace", SCENE, "--width", "8", "--height", "8", "--pixel", "4,4", "--path", "1,2",
                    "-o", path_json], check=True, capture_output=True)
    commands = [
        ("--version", [b, "--version"]),
        ("info cornell-box.gltf", [b, "info", SCENE]),
        ("compare a.exr b.exr", [b, "compare", A, B]),
        ("mis path.json", [b, "mis", path_json]),
        ("render 8x8, 1 spp, 1 thread", tiny + ["--spp", "1", "-o", os.path.join(tmp, "r.exr")]),
        ("merge a.exr b.exr", [b, "merge", "-q", A, B, "-o", M]),
    ]
    samples = {name: ([], []) for name, _ in commands}
    for _ in range(a.runs):
        for name, cmd in commands:
            # compare exits 1 when the images are inconsistent: still a finished run.
            cpu, wall = run_once(cmd, (0, 1) if cmd[1] == "compare" else (0,))
            samples[name][0].append(cpu)
            samples[name][1].append(wall)
    print("| command | CPU ms (median of %d) | wall ms (median) |" % a.runs)
    print("|---|---:|---:|")
    for name, _ in commands:
        cpu, wall = samples[name]
        print("| `%s` | %.1f | %.1f |" % (name, 1e3 * statistics.median(cpu), 1e3 * statistics.median(wall)))


if __name__ == "__main__":
    main()
