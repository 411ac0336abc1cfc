#!/usr/bin/python3
"""Writes the two scenes of the light-tree benchmark (bench/README.md, "Many lights: the light tree").

    python3 bench/make_many_lights.py [--out /tmp/many-lights] [--lights 4000] [--grid 48]

many-lights.gltf: a room 2R x 4 x 2R (R = --room, default 5; grey Lambert walls, six box pillars that hide parts of it)
with --lights small one-sided emissive quads (2 triangles each, so 2 x --lights area lights) on the
ceiling and the walls above 3 m, facing into the room, 3-12 cm wide, of random hue and an emissive strength
log-uniform over four decades (64 materials, KHR_materials_emissive_strength): thousands of
emitters of varied power, most of them far from any given point or facing away from it. The camera
(at 1.7 m, pitched 25 degrees down) sees the floor, the pillars and the walls below 3 m, not the
emitters: the error measured is that of the lighting (a seen emitter adds the same pixel-sampling
noise with either light sampler).

emissive-texture.gltf: the same room without the small lights, lit by one ceiling panel of
--grid x --grid quads (2 x grid^2 area lights) with an emissive texture that is black (--background)
except for a few dozen bright spots, so that most triangles emit almost nothing (the light power of a textured
triangle is the texture's estimate, docs/lights.md "Emissive textures").

Standard library only; deterministic (seeded). Written to /tmp, never committed.
"""
import argparse
import json
import math
import os
import random
import struct
import zlib

ROOM_W, ROOM_H, ROOM_D = 5.0, 4.0, 5.0  # half-width (x), height (y), half-depth (z); --room sets W = D


def png_rgb(width, height, pixel):
    """An 8-bit RGB PNG; pixel(x, y) -> (r, g, b) bytes."""
    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = bytearray()
    for y in range(height):
        raw += b"\x00" + bytes(v for x in range(width) for v in pixel(x, y))
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def add3(a, b):
    return [a[i] + b[i] for i in range(3)]


def scale(a, s):
    return [x * s for x in a]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def quad(centre, normal, tangent, half_u, half_v):
    """Four corners of a quad facing `normal` (counter-clockwise seen from the front) and its uvs."""
    u = scale(tangent, half_u)
    v = scale(cross(normal, tangent), half_v)  # u x v is along normal
    corners = [add3(add3(centre, scale(u, su)), scale(v, sv)) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return corners, [[0, 0], [1, 0], [1, 1], [0, 1]]


class Mesh:
    """Triangles of one material: positions, uvs and indices."""
    def __init__(self):
        self.pos, self.uv, self.idx = [], [], []

    def add_quad(self, corners, uvs):
        base = len(self.pos) // 3
        for c in corners:
            self.pos += c
        for t in uvs:
            self.uv += t
        self.idx += [base, base + 1, base + 2, base, base + 2, base + 3]


def room(mesh):
    """Floor, ceiling and walls facing inward."""
    W, H, D = ROOM_W, ROOM_H, ROOM_D
    faces = [([0, 0, 0], [0, 1, 0], [1, 0, 0], W, D), ([0, H, 0], [0, -1, 0], [1, 0, 0], W, D),
             ([-W, H / 2, 0], [1, 0, 0], [0, 0, 1], D, H / 2), ([W, H / 2, 0], [-1, 0, 0], [0, 0, 1], D, H / 2),
             ([0, H / 2, -D], [0, 0, 1], [1, 0, 0], W, H / 2), ([0, H / 2, D], [0, 0, -1], [1, 0, 0], W, H / 2)]
    for centre, n, t, hu, hv in faces:
        mesh.add_quad(*quad(centre, n, t, hu, hv))


def pillars(mesh, rng):
    """Six boxes standing on the floor (outward faces)."""
    for k in range(6):
        cx, cz = -3.2 + 1.3 * k, (-1.5 if k % 2 else 1.0) + rng.uniform(-0.5, 0.5)
        hx, hz, h = 0.35, 0.35, rng.uniform(1.5, 3.2)
        faces = [([cx, h, cz], [0, 1, 0], [1, 0, 0], hx, hz),
                 ([cx - hx, h / 2, cz], [-1, 0, 0], [0, 0, 1], hz, h / 2), ([cx + hx, h / 2, cz], [1, 0, 0], [0, 0, 1], hz, h / 2),
                 ([cx, h / 2, cz - hz], [0, 0, -1], [1, 0, 0], hx, h / 2), ([cx, h / 2, cz + hz], [0, 0, 1], [1, 0, 0], hx, h / 2)]
        for centre, n, t, hu, hv in faces:
            mesh.add_quad(*quad(centre, n, t, hu, hv))


def random_light_placement(rng):
    """A point on the ceiling or a wall, just inside the room, with the inward normal and a tangent."""
    W, H, D = ROOM_W, ROOM_H, ROOM_D
    eps = 2e-3
    side = rng.random()
    if side < 0.5:
        return [rng.uniform(-W + 0.2, W - 0.2), H - eps, rng.uniform(-D + 0.2, D - 0.2)], [0, -1, 0], [1, 0, 0]
    wall = rng.randrange(4)
    y = rng.uniform(3.0, H - 0.1)
    a = rng.uniform(-0.96, 0.96)
    if wall == 0:
        return [-W + eps, y, a * D], [1, 0, 0], [0, 0, 1]
    if wall == 1:
        return [W - eps, y, a * D], [-1, 0, 0], [0, 0, 1]
    if wall == 2:
        return [a * W, y, -D + eps], [0, 0, 1], [1, 0, 0]
    return [a * W, y, D - eps], [0, 0, -1], [1, 0, 0]


def hue(rng):
    h = rng.random() * 6
    x = 1 - abs(h % 2 - 1)
    r, g, b = [(1, x, 0), (x, 1, 0), (0, 1, x), (0, x, 1), (x, 0, 1), (1, 0, x)][int(h)]
    return [0.3 + 0.7 * r, 0.3 + 0.7 * g, 0.3 + 0.7 * b]


class Document:
    def __init__(self, name, pitch_quaternion_x):
        self.buf = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "bdptref bench/make_many_lights.py"},
                    "extensionsUsed": ["KHR_materials_emissive_strength"],
                    "scene": 0, "scenes": [{"nodes": [0]}],
                    "nodes": [{"camera": 0, "translation": [0.0, 1.7, ROOM_D - 0.4], "rotation": [pitch_quaternion_x, 0.0, 0.0, math.sqrt(1 - pitch_quaternion_x ** 2)]}],
                    "cameras": [{"type": "perspective", "perspective": {"yfov": 1.1, "aspectRatio": 1.0, "znear": 0.01}}],
                    "meshes": [], "materials": [], "accessors": [], "bufferViews": [], "buffers": []}
        self.name = name

    def accessor(self, fmt, values, kind, count, target, comp, bounds=False):
        while len(self.buf) % 4:
            self.buf.append(0)
        data = struct.pack("<%d%s" % (len(values), fmt), *values)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.buf), "byteLength": len(data), "target": target})
        self.buf.extend(data)
        acc = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": comp, "count": count, "type": kind}
        if bounds:
            acc["min"] = [min(values[i::3]) for i in range(3)]
            acc["max"] = [max(values[i::3]) for i in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def add_mesh(self, mesh, material, uvs=False):
        n = len(mesh.pos) // 3
        attrs = {"POSITION": self.accessor("f", mesh.pos, "VEC3", n, 34962, 5126, bounds=True)}
        if uvs:
            attrs["TEXCOORD_0"] = self.accessor("f", mesh.uv, "VEC2", n, 34962, 5126)
        i = self.accessor("I", mesh.idx, "SCALAR", len(mesh.idx), 34963, 5125)
        self.doc["meshes"].append({"primitives": [{"attributes": attrs, "indices": i, "material": material}]})
        self.doc["nodes"].append({"mesh": len(self.doc["meshes"]) - 1})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def material(self, m):
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def write(self, folder):
        with open(os.path.join(folder, self.name + ".bin"), "wb") as f:
            f.write(self.buf)
        self.doc["buffers"].append({"uri": self.name + ".bin", "byteLength": len(self.buf)})
        path = os.path.join(folder, self.name + ".gltf")
        with open(path, "w") as f:
            json.dump(self.doc, f)
        return path


def grey_room(doc, rng):
    walls = Mesh()
    room(walls)
    pillars(walls, rng)
    doc.add_mesh(walls, doc.material({"name": "walls", "pbrMetallicRoughness": {
        "baseColorFactor": [0.6, 0.6, 0.6, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}))


def many_lights(folder, count, rng):
    doc = Document("many-lights", -0.2164)  # 25 degrees down: the emitters are out of view
    grey_room(doc, rng)
    groups = 64
    meshes = [Mesh() for _ in range(groups)]
    for _ in range(count):
        centre, n, t = random_light_placement(rng)
        size = rng.uniform(0.015, 0.06)
        meshes[rng.randrange(groups)].add_quad(*quad(centre, n, t, size, size))
    for g, mesh in enumerate(meshes):
        strength = 10 ** (-2 + 4 * (g + 0.5) / groups)  # 10^-2 .. 10^2, log-uniform
        m = doc.material({"name": "light%d" % g, "emissiveFactor": hue(rng),
                          "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength}},
                          "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0}})
        if mesh.idx:
            doc.add_mesh(mesh, m)
    return doc.write(folder), 2 * count


def emissive_texture(folder, grid, background, rng):
    doc = Document("emissive-texture", -0.0998)  # 11.5 degrees down: the panel's near edge in view
    grey_room(doc, rng)
    size = 256
    spots = [(rng.randrange(size), rng.randrange(size), rng.choice([2, 3, 5])) for _ in range(40)]
    def pixel(x, y):
        for sx, sy, r in spots:
            if (x - sx) ** 2 + (y - sy) ** 2 <= r * r:
                return (255, 240, 200)
        return (background, background, background)
    with open(os.path.join(folder, "emissive-spots.png"), "wb") as f:
        f.write(png_rgb(size, size, pixel))
    doc.doc["images"] = [{"uri": "emissive-spots.png"}]
    doc.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728}]
    doc.doc["textures"] = [{"source": 0, "sampler": 0}]
    panel = Mesh()
    half = 3.5
    for j in range(grid):
        for i in range(grid):
            cx = -half + (i + 0.5) * 2 * half / grid
            cz = -half + (j + 0.5) * 2 * half / grid
            corners, _ = quad([cx, ROOM_H - 2e-3, cz], [0, -1, 0], [1, 0, 0], half / grid, half / grid)
            uvs = [[(i + a) / grid, (j + b) / grid] for a, b in ((0, 0), (1, 0), (1, 1), (0, 1))]
            panel.add_quad(corners, uvs)
    m = doc.material({"name": "spots", "emissiveFactor": [1.0, 1.0, 1.0], "emissiveTexture": {"index": 0},
                      "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
                      "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0}})
    doc.add_mesh(panel, m, uvs=True)
    return doc.write(folder), 2 * grid * grid


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="/tmp/many-lights", help="output folder (default /tmp/many-lights)")
    ap.add_argument("--lights", type=int, default=4000, help="emissive quads in many-lights.gltf (default 4000)")
    ap.add_argument("--grid", type=int, default=48, help="quads per side of the emissive-texture panel (default 48)")
    ap.add_argument("--room", type=float, default=5.0, help="half-width and half-depth of many-lights.gltf's room in m (default 5)")
    ap.add_argument("--background", type=int, default=1,
                    help="the emissive texture's value (0-255, sRGB) outside the spots (default 1)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    global ROOM_W, ROOM_D
    ROOM_W = ROOM_D = args.room  # many-lights.gltf only
    path, n = many_lights(args.out, args.lights, random.Random(31))
    ROOM_W = ROOM_D = 5.0
    print("%s: %d emissive triangles" % (path, n))
    path, n = emissive_texture(args.out, args.grid, args.background, random.Random(32))
    print("%s: %d emissive triangles (textured)" % (path, n))


if __name__ == "__main__":
    main()
