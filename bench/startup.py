#!/usr/bin/python3
"""Start-up cost of the bdptref CLI: CPU-seconds (user + sys of the child, from wait4) and wall
time of short commands, median of N runs each, interleaved so machine noise hits all alike.

    bench/startup.py [--binary build/bdptref [--binary OTHER ...]] [--runs 15]

Prints a Markdown table (bench/README.md, "Start-up"), one column pair per binary (e.g. a copy of
an older build next to the current one: runs are interleaved, so both see the same load). The
inputs (two 8x8 renders, a path JSON) are made first with the first binary in a temporary folder
and are not timed. Not a test: nothing is asserted.
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
    ap.add_argument("--binary", action="append", help="bdptref binary (repeatable; default build/bdptref)")
    ap.add_argument("--runs", type=int, default=15)
    a = ap.parse_args()
    binaries = [os.path.abspath(x) for x in (a.binary or [os.path.join(ROOT, "build", "bdptref")])]
    b = binaries[0]
    tmp = tempfile.mkdtemp(prefix="bdptref-startup-")
    A, B, M = (os.path.join(tmp, n) for n in ("a.exr", "b.exr", "m.exr"))
    tiny = [b, "render", SCENE, "--width", "8", "--height", "8", "--threads", "1"]
    subprocess.run(tiny + ["-o", A, "--sample-range", "0:2"], check=True, capture_output=True)
    subprocess.run(tiny + ["-o", B, "--sample-range", "2:4"], check=True, capture_output=True)
    path_json = os.path.join(tmp, "path.json")
    subprocess.run([b, "trace", SCENE, "--width", "8", "--height", "8", "--pixel", "4,4", "--path", "1,2",
                    "-o", path_json], check=True, capture_output=True)
    def commands(b):
        tiny_b = [b] + tiny[1:]
        return [
            ("--version", [b, "--version"]),
            ("info cornell-box.gltf", [b, "info", SCENE]),
            ("compare a.exr b.exr", [b, "compare", A, B]),
            ("mis path.json", [b, "mis", path_json]),
            ("render 8x8, 1 spp, 1 thread", tiny_b + ["--spp", "1", "-o", os.path.join(tmp, "r.exr")]),
            ("merge a.exr b.exr", [b, "merge", "-q", A, B, "-o", M]),
        ]
    names = [name for name, _ in commands(b)]
    samples = {(bi, name): ([], []) for bi in range(len(binaries)) for name in names}
    for _ in range(a.runs):
        for name_index in range(len(names)):
            for bi, binary in enumerate(binaries):
                name, cmd = commands(binary)[name_index]
                # compare exits 1 when the images are inconsistent and 2 when 1-spp inputs allow
                # no verdict: still a finished run.
                cpu, wall = run_once(cmd, (0, 1, 2) if cmd[1] == "compare" else (0,))
                samples[(bi, name)][0].append(cpu)
                samples[(bi, name)][1].append(wall)
    print("Medians of %d interleaved runs; CPU = user + sys of the process." % a.runs)
    for bi, binary in enumerate(binaries):
        print("- binary %d: %s" % (bi + 1, binary))
    print()
    print("| command |" + "".join(" CPU ms (%d) | wall ms (%d) |" % (bi + 1, bi + 1) for bi in range(len(binaries))))
    print("|---|" + "---:|---:|" * len(binaries))
    for name in names:
        row = "| `%s` |" % name
        for bi in range(len(binaries)):
            cpu, wall = samples[(bi, name)]
            row += " %.1f | %.1f |" % (1e3 * statistics.median(cpu), 1e3 * statistics.median(wall))
        print(row)


if __name__ == "__main__":
    main()
