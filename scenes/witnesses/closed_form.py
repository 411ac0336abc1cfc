#!/usr/bin/env python3
"""The closed-form images of the witness scenes, and a renderer's renders measured against them.

    scenes/witnesses/closed_form.py SCENE.gltf --size 32x32 --max-depth N  RENDER.exr [RENDER.exr ...]

prints the relative bias of the mean of the renders against the closed form, with its standard
error from the spread of the renders (N - 1 degrees of freedom), over the image and per row of
pixels (the rows are where a grazing-angle error shows). EXRs are read with oiiotool --dumpdata
(package openimageio-tools). Needs numpy.
"""
import argparse
import json
import math
import subprocess
import sys

import numpy as np


def read_exr(path):
    out = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    lines = out.splitlines()
    w, h = [int(t) for t in lines[0].split(":")[1].split(",")[0].split("x")]
    img = np.zeros((h, w, 3))
    for ln in lines[1:]:
        if "Pixel (" not in ln:
            continue
        head, vals = ln.split(":", 1)
        x, y = [int(t) for t in head.split("(")[1].rstrip(")").split(",")]
        img[y, x] = [float(v) for v in vals.split()[:3]]
    return img


def polygon_radiance(p, n, verts, rho, le):
    """rho/pi * Le * (irradiance factor) at points p (..., 3) of normal n from a polygon (Lambert)."""
    total = np.zeros(p.shape[:-1])
    k = len(verts)
    for i in range(k):
        a = verts[i] - p
        b = verts[(i + 1) % k] - p
        a /= np.linalg.norm(a, axis=-1, keepdims=True)
        b /= np.linalg.norm(b, axis=-1, keepdims=True)
        c = np.cross(a, b)
        cn = np.linalg.norm(c, axis=-1)
        theta = np.arctan2(cn, np.sum(a * b, axis=-1))
        with np.errstate(invalid="ignore", divide="ignore"):
            total += np.where(cn > 0, theta * (c @ n) / np.where(cn > 0, cn, 1), 0.0)
    return rho * le / (2.0 * math.pi) * np.abs(total)


def light_wall_image(params, w, h, q=16):
    cam = np.array(params["camera"])
    ymag = params["ymag"]
    xmag = ymag * w / h
    y0 = params["light_y"]
    lx, lz = params["light_x"], params["light_z"]
    verts = [np.array(v) for v in ((lx[0], y0, lz[0]), (lx[1], y0, lz[0]), (lx[1], y0, lz[1]), (lx[0], y0, lz[1]))]
    img = np.zeros((h, w))
    s = (np.arange(q) + 0.5) / q
    for j in range(h):
        ry = j + s
        wy = cam[1] + (1 - 2 * ry / h) * ymag
        for i in range(w):
            rx = i + s
            wz = cam[2] - (2 * rx / w - 1) * xmag  # camera right = -z
            Y, Z = np.meshgrid(wy, wz, indexing="ij")
            p = np.stack([np.full_like(Y, params["wall_x"]), Y, Z], axis=-1)
            img[j, i] = polygon_radiance(p, np.array([1.0, 0.0, 0.0]), verts, params["rho"], params["Le"]).mean()
    return np.repeat(img[:, :, None], 3, axis=2)


def closed_form(scene, w, h, max_depth, q=16):
    js = json.load(open(scene))
    ex = js["scenes"][0]["extras"]
    params = ex["analytic_params"]
    if "light_x" in params:
        if max_depth != 1:
            sys.exit("the light-wall witnesses have a closed form at --max-depth 1 only")
        return light_wall_image(params, w, h, q)
    rho, le = params["rho"], params["Le"]
    return np.full((h, w, 3), le * (1 - rho ** (max_depth + 1)) / (1 - rho))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("renders", nargs="+")
    ap.add_argument("--size", default="32x32")
    ap.add_argument("--max-depth", type=int, required=True)
    ap.add_argument("--quadrature", type=int, default=16, help="points per pixel side (default 16)")
    ap.add_argument("--rows", action="store_true", help="print every row")
    a = ap.parse_args()
    w, h = [int(t) for t in a.size.split("x")]
    ref = closed_form(a.scene, w, h, a.max_depth, a.quadrature)
    imgs = np.array([read_exr(p) for p in a.renders])
    n = len(imgs)
    # per render: its image mean relative to the closed form's; the spread over renders is the noise
    rel = imgs.mean(axis=(1, 2, 3)) / ref.mean() - 1
    se = rel.std(ddof=1) / math.sqrt(n) if n > 1 else float("nan")
    print("%s: %d renders, image: %+.4f%% +- %.4f%% (closed form mean %.6g)" % (a.scene, n, 100 * rel.mean(), 100 * se, ref.mean()))
    if a.rows or "light_x" in json.load(open(a.scene))["scenes"][0]["extras"]["analytic_params"]:
        rows = imgs.mean(axis=(2, 3)) / ref.mean(axis=(1, 2)) - 1
        for j in range(h) if a.rows else range(min(h, 8)):
            r = rows[:, j]
            print("  row %2d: %+.3f%% +- %.3f%% (closed form %.6g)" % (j, 100 * r.mean(), 100 * r.std(ddof=1) / math.sqrt(n),
                                                                   ref[j].mean()))


if __name__ == "__main__":
    main()
