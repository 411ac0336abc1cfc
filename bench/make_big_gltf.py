#!/usr/bin/python3
"""Writes a FlightHelmet-sized glTF for measuring scene loading (time and peak memory).

    python3 bench/make_big_gltf.py [--out /tmp/big-gltf] [--materials 6] [--size 2048] [--quads 128x64]
    /usr/bin/time -v build/bdptref info /tmp/big-gltf/big.gltf

Each material gets its own grid of (quads) x 2 triangles and two textures of size x size: an
sRGB base colour (RGB) and a linear occlusion-roughness-metallic image (RGB), like FlightHelmet's
5 materials with 2048^2 maps. The defaults give 6 grids of 16 384 triangles (98 304 in all) and
12 textures of 2048 x 2048. Texels are smooth bands plus 5 bits of noise, so PNG compression does
about what it does on photographs (the files are ~60 % of the raw size); pure noise would not
compress at all and a flat image would compress to nothing. Standard library only (zlib, struct);
deterministic (seeded). Written to /tmp, never committed.
"""
import argparse
import json
import os
import random
import struct
import zlib


def png(width, height, channels, rows):
    """A PNG (8 bit, RGB or RGBA) from an iterable of raw rows (bytes of width*channels)."""
    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    colour_type = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    raw = bytearray()
    for r in rows:
        raw += b"\x00" + r  # filter 0 (none) on each row
    ihdr = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(bytes(raw), 6)) + chunk(b"IEND", b"")


def noise_rows(width, height, channels, rng):
    """Rows of smooth bands (the row's base level drifts) plus 5 bits of per-texel noise."""
    level = rng.randrange(0, 224)
    tables = {}
    for _ in range(height):
        level = min(223, max(0, level + rng.randrange(-2, 3)))
        if level not in tables:
            tables[level] = bytes((level + (n & 31)) for n in range(256))
        yield rng.randbytes(width * channels).translate(tables[level])


def grid(nx, ny, x0, z0):
    """A flat grid of nx x ny quads on y = 0 with normals +y and uv over [0,1]^2."""
    pos, nrm, uv, idx = [], [], [], []
    for j in range(ny + 1):
        for i in range(nx + 1):
            u, v = i / nx, j / ny
            pos += [x0 + u, 0.0, z0 + v]
            nrm += [0.0, 1.0, 0.0]
            uv += [u, v]
    for j in range(ny):
        for i in range(nx):
            a = j * (nx + 1) + i
            b, c, d = a + 1, a + nx + 1, a + nx + 2
            idx += [a, c, b, b, c, d]
    return pos, nrm, uv, idx


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="/tmp/big-gltf", help="output folder (default /tmp/big-gltf)")
    ap.add_argument("--materials", type=int, default=6, help="materials (2 textures each; default 6)")
    ap.add_argument("--size", type=int, default=2048, help="texture side in texels (default 2048)")
    ap.add_argument("--quads", default="128x64", help="quads per material grid (default 128x64)")
    args = ap.parse_args()
    nx, ny = (int(s) for s in args.quads.split("x"))
    os.makedirs(args.out, exist_ok=True)
    rng = random.Random(13)

    buf = bytearray()
    doc = {"asset": {"version": "2.0", "generator": "bdptref bench/make_big_gltf.py"},
           "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "materials": [],
           "accessors": [], "bufferViews": [], "buffers": [], "images": [], "textures": [],
           "samplers": [{"magFilter": 9729, "minFilter": 9987}]}

    def add(fmt, values, kind, count, target, comp, bounds=False):
        while len(buf) % 4:
            buf.append(0)
        data = struct.pack("<%d%s" % (len(values), fmt), *values)
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data), "target": target})
        buf.extend(data)
        acc = {"bufferView": len(doc["bufferViews"]) - 1, "componentType": comp, "count": count, "type": kind}
        if bounds:  # POSITION accessors must carry min and max
            acc["min"] = [min(values[i::3]) for i in range(3)]
            acc["max"] = [max(values[i::3]) for i in range(3)]
        doc["accessors"].append(acc)
        return len(doc["accessors"]) - 1

    triangles = 0
    for m in range(args.materials):
        images = []
        for k, name in enumerate(("basecolor", "orm")):
            fname = "m%d_%s.png" % (m, name)
            with open(os.path.join(args.out, fname), "wb") as f:
                f.write(png(args.size, args.size, 3, noise_rows(args.size, args.size, 3, rng)))
            doc["images"].append({"uri": fname})
            doc["textures"].append({"source": len(doc["images"]) - 1, "sampler": 0})
            images.append(len(doc["textures"]) - 1)
        doc["materials"].append({"name": "m%d" % m, "pbrMetallicRoughness": {
            "baseColorTexture": {"index": images[0]}, "metallicRoughnessTexture": {"index": images[1]}}})
        pos, nrm, uv, idx = grid(nx, ny, 1.1 * (m % 3), 1.1 * (m // 3))
        count = len(pos) // 3
        p = add("f", pos, "VEC3", count, 34962, 5126, bounds=True)
        n = add("f", nrm, "VEC3", count, 34962, 5126)
        t = add("f", uv, "VEC2", count, 34962, 5126)
        i = add("I", idx, "SCALAR", len(idx), 34963, 5125)
        doc["meshes"].append({"primitives": [{"attributes": {"POSITION": p, "NORMAL": n, "TEXCOORD_0": t},
                                              "indices": i, "material": m}]})
        doc["nodes"].append({"mesh": m})
        doc["scenes"][0]["nodes"].append(m)
        triangles += len(idx) // 3
    with open(os.path.join(args.out, "big.bin"), "wb") as f:
        f.write(buf)
    doc["buffers"].append({"uri": "big.bin", "byteLength": len(buf)})
    with open(os.path.join(args.out, "big.gltf"), "w") as f:
        json.dump(doc, f)
    total = sum(os.path.getsize(os.path.join(args.out, x["uri"])) for x in doc["images"])
    print("%s: %d triangles, %d textures of %d x %d (%.1f MB of PNG)" %
          (os.path.join(args.out, "big.gltf"), triangles, len(doc["textures"]), args.size, args.size, total / 1e6))


if __name__ == "__main__":
    main()
