#!/usr/bin/env python3
"""Deterministic generator for the bdptref test scenes (glTF 2.0).

Run `python3 scenes/generate.py` from anywhere: it rewrites every scene into the folder this
script lives in. Standard library only. The output is byte-identical from run to run:
vertex data is packed as little-endian float32 / uint, JSON is written with sorted keys and
fixed separators, and every float written to JSON is either rounded to 9 significant digits
(material/camera parameters) or is the exact value of a float32 from the buffer (accessor
min/max), so that min/max match the binary data exactly under float or double comparison.

Conventions (see scenes/README.md):
  * materials are pure Lambertian: metallicFactor 0, roughnessFactor 1,
    KHR_materials_specular.specularFactor 0, albedo = baseColorFactor;
  * emitted radiance Le is written as emissiveFactor = Le / max(Le) plus
    KHR_materials_emissive_strength.emissiveStrength = max(Le);
  * emission is one-sided (front face = counter-clockwise winding) unless doubleSided; every
    triangle's winding agrees with the NORMAL written for its vertices;
  * cameras look down their local -Z with +Y up.
"""

import base64
import json
import math
import os
import struct

GENERATOR = "bdptref scenes/generate.py"
OUT_DIR = os.path.dirname(os.path.abspath(__file__))

FLOAT = 5126
UNSIGNED_SHORT = 5123
UNSIGNED_INT = 5125
ARRAY_BUFFER = 34962
ELEMENT_ARRAY_BUFFER = 34963


# ---------------------------------------------------------------------------------------------
# small vector helpers (tuples of Python floats)

def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a):
    length = math.sqrt(dot(a, a))
    return (a[0] / length, a[1] / length, a[2] / length)


def centroid(points):
    n = float(len(points))
    s = (0.0, 0.0, 0.0)
    for p in points:
        s = add(s, p)
    return scale(s, 1.0 / n)


def num(x):
    """A JSON float with fixed formatting: rounded to 9 significant digits."""
    return float("%.9g" % x)


def f32(x):
    """The exact value (as a Python float) of x rounded to float32."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


# ---------------------------------------------------------------------------------------------
# mesh building

class Mesh:
    """Indexed triangles with per-vertex positions and normals, all in world space."""

    def __init__(self, name, material, index_type=UNSIGNED_SHORT):
        self.name = name
        self.material = material
        self.index_type = index_type
        self.positions = []
        self.normals = []
        self.triangles = []
        self.uvs = None  # per-vertex TEXCOORD_0 (u, v) when set: a list parallel to positions
        self.instances = None  # list of node translations: one node per instance (loader copies the mesh)

    def vertex(self, p, n):
        self.positions.append(tuple(float(c) for c in p))
        self.normals.append(normalize(n))
        return len(self.positions) - 1

    def flat_polygon(self, points, facing):
        """A planar convex polygon (or a possibly non-planar quad) with flat normals, wound so
        that its geometric normal points along `facing` (a direction vector).

        Planar polygons share their vertices (one face normal); a non-planar quad is split
        into two triangles (v0,v1,v2),(v0,v2,v3) with their own vertices and face normals."""
        pts = [tuple(float(c) for c in p) for p in points]
        n = face_normal(pts)
        if dot(n, facing) < 0:
            pts = [pts[0]] + pts[:0:-1]  # reverse the winding, keep v0
            n = scale(n, -1.0)
        tris = [(0, i, i + 1) for i in range(1, len(pts) - 1)]
        tri_normals = [normalize(cross(sub(pts[b], pts[a]), sub(pts[c], pts[a]))) for a, b, c in tris]
        planar = all(dot(tn, n) > 1.0 - 1e-12 for tn in tri_normals)
        if planar:
            ids = [self.vertex(p, n) for p in pts]
            for a, b, c in tris:
                self.triangles.append((ids[a], ids[b], ids[c]))
        else:
            for (a, b, c), tn in zip(tris, tri_normals):
                assert dot(tn, facing) > 0
                self.triangles.append(tuple(self.vertex(pts[k], tn) for k in (a, b, c)))

    def triangle_count(self):
        return len(self.triangles)


def face_normal(pts):
    """Newell's method: the unit normal of a polygon with counter-clockwise winding."""
    nx = ny = nz = 0.0
    for i in range(len(pts)):
        a = pts[i]
        b = pts[(i + 1) % len(pts)]
        nx += (a[1] - b[1]) * (a[2] + b[2])
        ny += (a[2] - b[2]) * (a[0] + b[0])
        nz += (a[0] - b[0]) * (a[1] + b[1])
    return normalize((nx, ny, nz))


def icosphere(level):
    """Unit icosphere: (positions, triangles) with shared vertices on the sphere, triangles
    wound counter-clockwise seen from outside (geometric normal pointing outward)."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    base = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
            (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
            (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [normalize(tuple(float(c) for c in v)) for v in base]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
             (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
             (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
             (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        cache = {}

        def midpoint(i, j):
            key = (i, j) if i < j else (j, i)
            if key not in cache:
                verts.append(normalize(scale(add(verts[i], verts[j]), 0.5)))
                cache[key] = len(verts) - 1
            return cache[key]

        new_faces = []
        for a, b, c in faces:
            ab = midpoint(a, b)
            bc = midpoint(b, c)
            ca = midpoint(c, a)
            new_faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new_faces
    for a, b, c in faces:
        g = cross(sub(verts[b], verts[a]), sub(verts[c], verts[a]))
        assert dot(g, centroid([verts[a], verts[b], verts[c]])) > 0, "icosphere winding"
    return verts, faces


def smooth_icosphere_mesh(name, material, level, radius, inward, index_type):
    verts, faces = icosphere(level)
    mesh = Mesh(name, material, index_type)
    sign = -1.0 if inward else 1.0
    for v in verts:
        mesh.vertex(scale(v, radius), scale(v, sign))
    for a, b, c in faces:
        mesh.triangles.append((a, c, b) if inward else (a, b, c))
    return mesh


def flat_icosphere_mesh(name, material, level, radius, index_type):
    """Outward-facing icosphere with flat face normals (three vertices per triangle)."""
    verts, faces = icosphere(level)
    mesh = Mesh(name, material, index_type)
    for a, b, c in faces:
        p = [scale(verts[k], radius) for k in (a, b, c)]
        n = cross(sub(p[1], p[0]), sub(p[2], p[0]))
        mesh.triangles.append(tuple(mesh.vertex(q, n) for q in p))
    return mesh


# ---------------------------------------------------------------------------------------------
# glTF document assembly

def lambert(name, albedo, emission=None, double_sided=False):
    m = {
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [num(albedo[0]), num(albedo[1]), num(albedo[2]), 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 1.0,
        },
        "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}},
        "doubleSided": double_sided,
    }
    if emission is not None:
        strength = max(emission)
        m["emissiveFactor"] = [num(c / strength) for c in emission]
        m["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": num(strength)}
    return m


class Document:
    def __init__(self, description, analytic=None, analytic_params=None):
        self.description = description
        self.analytic = analytic
        self.analytic_params = analytic_params
        self.materials = []
        self.material_index = {}
        self.meshes = []
        self.camera = None
        self.lights = []

    def material(self, mat):
        if mat["name"] not in self.material_index:
            self.material_index[mat["name"]] = len(self.materials)
            self.materials.append(mat)
        return self.material_index[mat["name"]]

    def add_mesh(self, mesh):
        self.meshes.append(mesh)

    def set_camera(self, name, translation, rotation, yfov, aspect=1.0, znear=None):
        persp = {"yfov": num(yfov), "aspectRatio": num(aspect)}
        persp["znear"] = num(znear) if znear is not None else 0.001
        self.camera = (name, [num(c) for c in translation], rotation, persp)

    def add_point_light(self, name, position, color, intensity):
        self.lights.append((name, [num(c) for c in position], [num(c) for c in color], num(intensity)))

    def build(self):
        """Returns (gltf dict without buffer uri, binary buffer bytes)."""
        blob = bytearray()
        buffer_views = []
        accessors = []

        def push(data, target):
            while len(blob) % 4:
                blob.append(0)
            buffer_views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data),
                                 "target": target})
            blob.extend(data)
            return len(buffer_views) - 1

        gltf_meshes = []
        nodes = []
        for mesh in self.meshes:
            # positions, with exact float32 min/max
            pos32 = [tuple(f32(c) for c in p) for p in mesh.positions]
            pdata = b"".join(struct.pack("<3f", *p) for p in pos32)
            pv = push(pdata, ARRAY_BUFFER)
            accessors.append({
                "bufferView": pv, "byteOffset": 0, "componentType": FLOAT,
                "count": len(pos32), "type": "VEC3",
                "min": [min(p[k] for p in pos32) for k in range(3)],
                "max": [max(p[k] for p in pos32) for k in range(3)],
            })
            pacc = len(accessors) - 1
            ndata = b"".join(struct.pack("<3f", *n) for n in mesh.normals)
            nv = push(ndata, ARRAY_BUFFER)
            accessors.append({"bufferView": nv, "byteOffset": 0, "componentType": FLOAT,
                              "count": len(mesh.normals), "type": "VEC3"})
            nacc = len(accessors) - 1
            flat = [i for tri in mesh.triangles for i in tri]
            if mesh.index_type == UNSIGNED_SHORT:
                assert max(flat) < 65535
                idata = struct.pack("<%dH" % len(flat), *flat)
            else:
                idata = struct.pack("<%dI" % len(flat), *flat)
            iv = push(idata, ELEMENT_ARRAY_BUFFER)
            accessors.append({"bufferView": iv, "byteOffset": 0, "componentType": mesh.index_type,
                              "count": len(flat), "type": "SCALAR"})
            iacc = len(accessors) - 1
            attributes = {"POSITION": pacc, "NORMAL": nacc}
            if mesh.uvs is not None:
                assert len(mesh.uvs) == len(mesh.positions)
                uv = push(b"".join(struct.pack("<2f", *t) for t in mesh.uvs), ARRAY_BUFFER)
                accessors.append({"bufferView": uv, "byteOffset": 0, "componentType": FLOAT,
                                  "count": len(mesh.uvs), "type": "VEC2"})
                attributes["TEXCOORD_0"] = len(accessors) - 1
            gltf_meshes.append({
                "name": mesh.name,
                "primitives": [{
                    "attributes": attributes,
                    "indices": iacc,
                    "material": self.material(mesh.material),
                    "mode": 4,
                }],
            })
            if mesh.instances is None:
                nodes.append({"name": mesh.name, "mesh": len(gltf_meshes) - 1})
            else:
                for k, t in enumerate(mesh.instances):
                    nodes.append({"name": "%s_%d" % (mesh.name, k), "mesh": len(gltf_meshes) - 1,
                                  "translation": [num(c) for c in t]})
        while len(blob) % 4:
            blob.append(0)

        gltf = {
            "asset": {"version": "2.0", "generator": GENERATOR},
            "extensionsUsed": ["KHR_materials_specular"],
            "materials": self.materials,
            "meshes": gltf_meshes,
            "accessors": accessors,
            "bufferViews": buffer_views,
            "buffers": [{"byteLength": len(blob)}],
        }
        if any("emissiveFactor" in m for m in self.materials):
            gltf["extensionsUsed"].append("KHR_materials_emissive_strength")
        if self.camera is not None:
            name, translation, rotation, persp = self.camera
            gltf["cameras"] = [{"name": name, "type": "perspective", "perspective": persp}]
            nodes.append({"name": name, "camera": 0, "translation": translation, "rotation": rotation})
        if self.lights:
            gltf["extensionsUsed"].append("KHR_lights_punctual")
            gltf["extensions"] = {"KHR_lights_punctual": {"lights": []}}
            for i, (name, position, color, intensity) in enumerate(self.lights):
                gltf["extensions"]["KHR_lights_punctual"]["lights"].append(
                    {"name": name, "type": "point", "color": color, "intensity": intensity})
                nodes.append({"name": name, "translation": position,
                              "extensions": {"KHR_lights_punctual": {"light": i}}})
        gltf["extensionsUsed"].sort()
        gltf["nodes"] = nodes
        extras = {"description": self.description}
        if self.analytic is not None:
            extras["analytic"] = self.analytic
        if self.analytic_params is not None:
            extras["analytic_params"] = self.analytic_params
        gltf["scenes"] = [{"name": "scene", "nodes": list(range(len(nodes))), "extras": extras}]
        gltf["scene"] = 0
        return gltf, bytes(blob)


def dumps(obj):
    return json.dumps(obj, sort_keys=True, indent=1, separators=(",", ": "), ensure_ascii=True,
                      allow_nan=False)


def write_gltf(doc, filename):
    gltf, blob = doc.build()
    gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    text = dumps(gltf) + "\n"
    with open(os.path.join(OUT_DIR, filename), "wb") as f:
        f.write(text.encode("ascii"))


def write_glb(doc, filename):
    gltf, blob = doc.build()
    js = dumps(gltf).encode("ascii")
    js += b" " * ((4 - len(js) % 4) % 4)
    bin_chunk = blob + b"\0" * ((4 - len(blob) % 4) % 4)
    total = 12 + 8 + len(js) + 8 + len(bin_chunk)
    out = bytearray()
    out += struct.pack("<III", 0x46546C67, 2, total)       # "glTF", version 2, length
    out += struct.pack("<II", len(js), 0x4E4F534A) + js    # JSON chunk
    out += struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk  # BIN chunk
    assert len(out) == total
    with open(os.path.join(OUT_DIR, filename), "wb") as f:
        f.write(bytes(out))


# ---------------------------------------------------------------------------------------------
# scenes

CORNELL_DESCRIPTION = (
    "The Cornell box from Cornell's published measurements (units as given, mm-like), open "
    "at the front (z=0). Light: 130x105 quad at the ceiling height, facing down, radiance "
    "(17,12,4); the ceiling has a rectangular hole exactly under the light so that no faces "
    "are coplanar and overlapping. Lambertian albedos: white (0.725,0.71,0.68), red "
    "(0.63,0.065,0.05), green (0.14,0.45,0.091), light 0.78. Camera at (278,273,-800) "
    "looking along +z, yfov 39.3077 degrees. Reference-comparison scene (no closed form).")

CORNELL_SMALL_LIGHT_DESCRIPTION = (
    "The Cornell box of cornell-box.gltf with a small, bright light: the light quad shrunk "
    "about its centre (278, 548.8, 279.5) to 1/10 of each edge (13x10.5: x in [271.5,284.5], "
    "z in [274.25,284.75]) and its radiance scaled by 100 to (1700,1200,400), so that the "
    "emitted power is unchanged; the ceiling hole follows the light. Everything else as in "
    "cornell-box.gltf. Reference-comparison scene (no closed form) where the strategies differ "
    "strongly: hitting the light by BSDF sampling (s=0) is 100 times rarer than in cornell-box.")


def cornell_box(light_scale=1.0, description=CORNELL_DESCRIPTION):
    """The Cornell box. light_scale < 1 shrinks the light quad about its centre by that factor
    per edge and multiplies its radiance by 1/light_scale^2 (same emitted power)."""
    doc = Document(description)
    white = lambert("white", (0.725, 0.71, 0.68))
    red = lambert("red", (0.63, 0.065, 0.05))
    green = lambert("green", (0.14, 0.45, 0.091))
    radiance_scale = 1.0 / (light_scale * light_scale)
    light = lambert("light", (0.78, 0.78, 0.78),
                    emission=(17.0 * radiance_scale, 12.0 * radiance_scale, 4.0 * radiance_scale))
    # Light rectangle x in [lx0, lx1], z in [lz0, lz1] (the full-size one: [213,343] x [227,332]).
    lcx, lcz, lhx, lhz = 278.0, 279.5, 65.0 * light_scale, 52.5 * light_scale
    lx0, lx1, lz0, lz1 = lcx - lhx, lcx + lhx, lcz - lhz, lcz + lhz
    up, down = (0.0, 1.0, 0.0), (0.0, -1.0, 0.0)

    floor = Mesh("floor", white)
    floor.flat_polygon([(552.8, 0, 0), (0, 0, 0), (0, 0, 559.2), (549.6, 0, 559.2)], up)

    # Ceiling y=548.8 over x in [0,556], z in [0,559.2]: a 3x3 grid of quads minus the centre
    # cell, which is exactly the light's rectangle (grid => no T-junctions, shared vertices).
    ceiling = Mesh("ceiling", white)
    xs = [0.0, lx0, lx1, 556.0]
    zs = [0.0, lz0, lz1, 559.2]
    y = 548.8
    grid = {}

    def grid_vertex(i, j):
        if (i, j) not in grid:
            grid[(i, j)] = ceiling.vertex((xs[i], y, zs[j]), down)
        return grid[(i, j)]

    for j in range(3):
        for i in range(3):
            if i == 1 and j == 1:
                continue  # the hole under the light
            a, b = grid_vertex(i, j), grid_vertex(i + 1, j)
            c, d = grid_vertex(i + 1, j + 1), grid_vertex(i, j + 1)
            # a=(x0,z0), b=(x1,z0), c=(x1,z1): cross(b-a, c-a).y = -dx*dz < 0, i.e. facing -y.
            for tri in ((a, b, c), (a, c, d)):
                p = [ceiling.positions[k] for k in tri]
                assert cross(sub(p[1], p[0]), sub(p[2], p[0]))[1] < 0
                ceiling.triangles.append(tri)

    back = Mesh("back_wall", white)
    back.flat_polygon([(549.6, 0, 559.2), (0, 0, 559.2), (0, 548.8, 559.2), (556, 548.8, 559.2)],
                      (0.0, 0.0, -1.0))
    left = Mesh("green_wall", green)
    left.flat_polygon([(0, 0, 559.2), (0, 0, 0), (0, 548.8, 0), (0, 548.8, 559.2)], (1.0, 0.0, 0.0))
    right = Mesh("red_wall", red)
    right.flat_polygon([(552.8, 0, 0), (549.6, 0, 559.2), (556, 548.8, 559.2), (556, 548.8, 0)],
                       (-1.0, 0.0, 0.0))

    def block(name, height, corners):
        mesh = Mesh(name, white)
        top = [(x, float(height), z) for x, z in corners]
        mesh.flat_polygon(top, up)
        c = centroid([(x, 0.0, z) for x, z in corners])
        for k in range(len(corners)):
            x0, z0 = corners[k]
            x1, z1 = corners[(k + 1) % len(corners)]
            side = [(x0, 0.0, z0), (x1, 0.0, z1), (x1, float(height), z1), (x0, float(height), z0)]
            mid = centroid(side)
            outward = sub(mid, c)
            mesh.flat_polygon(side, (outward[0], 0.0, outward[2]))
        return mesh

    short_block = block("short_block", 165, [(130, 65), (82, 225), (240, 272), (290, 114)])
    tall_block = block("tall_block", 330, [(423, 247), (265, 296), (314, 456), (472, 406)])

    lamp = Mesh("light", light)
    lamp.flat_polygon([(lx1, 548.8, lz0), (lx1, 548.8, lz1), (lx0, 548.8, lz1), (lx0, 548.8, lz0)], down)

    for m in (floor, ceiling, back, left, right, short_block, tall_block, lamp):
        doc.add_mesh(m)
    # rotation [0,1,0,0]: 180 degrees about +y, turns the camera's -z view axis into +z.
    doc.set_camera("camera", (278.0, 273.0, -800.0), [0.0, 1.0, 0.0, 0.0],
                   math.radians(39.3077), aspect=1.0, znear=1.0)
    return doc


def furnace_box():
    rho = 0.5
    doc = Document(
        "Furnace test: closed cube [-1,1]^3, all six faces facing inward, every face a Lambertian "
        "of albedo 0.5 that emits white radiance Le=1 one-sided into the box. Camera at the "
        "centre looking along -z, yfov 60 degrees.",
        "Every pixel = Le*(1-rho^(N+1))/(1-rho) with rho=0.5, Le=1, where N is the maximum depth "
        "(N scattering events, N+1 path edges at most): N=0 -> 1, N=1 -> 1.5, N=2 -> 1.75, "
        "N=infinity -> 2.",
        {"rho": rho, "Le": 1.0, "radiance_infinite_depth": 2.0})
    mat = lambert("emissive_grey", (rho, rho, rho), emission=(1.0, 1.0, 1.0))
    box = Mesh("box", mat, UNSIGNED_INT)
    for axis in range(3):
        for s in (-1.0, 1.0):
            # face at coordinate `axis` = s, facing inward (-s along axis)
            u, v = [k for k in range(3) if k != axis]
            pts = []
            for a, b in ((-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = s, a, b
                pts.append(tuple(p))
            facing = [0.0, 0.0, 0.0]
            facing[axis] = -s
            box.flat_polygon(pts, tuple(facing))
    doc.add_mesh(box)
    doc.set_camera("camera", (0.0, 0.0, 0.0), [0.0, 0.0, 0.0, 1.0], math.radians(60.0))
    return doc


def sphere_point_light():
    rho, intensity, radius = 0.5, 1.0, 1.0
    doc = Document(
        "Closed sphere lit from inside: level-5 icosphere (20480 triangles, shared vertices, "
        "smooth normals) of radius 1 at the origin, wound and normalled to face inward, "
        "Lambertian albedo 0.5; a KHR_lights_punctual point light of colour (1,1,1) and "
        "intensity 1 at the origin; camera at the origin looking along -z, yfov 60 degrees.",
        "Every pixel = rho*I/(pi*R^2) * (1-rho^N)/(1-rho) at maximum depth N >= 1 (0 at N=0): "
        "direct irradiance I/R^2 at normal incidence, and each further bounce multiplies by rho "
        "because the sphere sees only itself. rho=0.5, I=1, R=1: N=1 -> 0.5/pi = 0.159154943, "
        "N=2 -> 0.75/pi, N=infinity -> 1/pi = 0.318309886. Exact for a true sphere; the flat "
        "facets lie slightly inside R=1, which raises the direct term by at most 6e-4 relative "
        "(at face centres; 0 at the vertices).",
        {"rho": rho, "I": intensity, "R": radius,
         "radiance_depth_1": num(rho * intensity / (math.pi * radius * radius)),
         "radiance_infinite_depth": num(rho * intensity / (math.pi * radius * radius) / (1.0 - rho))})
    mat = lambert("grey", (rho, rho, rho))
    doc.add_mesh(smooth_icosphere_mesh("sphere", mat, 5, radius, True, UNSIGNED_INT))
    doc.add_point_light("point_light", (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), intensity)
    doc.set_camera("camera", (0.0, 0.0, 0.0), [0.0, 0.0, 0.0, 1.0], math.radians(60.0))
    return doc


def env_sphere():
    rho = 0.5
    doc = Document(
        "Convex sphere under a constant environment: level-4 icosphere (5120 triangles, flat face "
        "normals) of radius 1 at the origin facing outward, Lambertian albedo 0.5, no lights "
        "(the environment is given on the command line). Camera at (0,0,3) looking along -z at "
        "the origin, yfov 20 degrees, aspect 1: the sphere covers the whole frame.",
        "Every pixel = rho*L_env = 0.5*L_env for maximum depth N >= 1 (0 at N=0): the surface is "
        "convex, so every point sees its whole hemisphere of unoccluded environment. Flat face "
        "normals keep this exact for the polyhedron.",
        {"rho": rho, "radiance_over_L_env": rho})
    mat = lambert("grey", (rho, rho, rho))
    doc.add_mesh(flat_icosphere_mesh("sphere", mat, 4, 1.0, UNSIGNED_INT))
    doc.set_camera("camera", (0.0, 0.0, 3.0), [0.0, 0.0, 0.0, 1.0], math.radians(20.0), aspect=1.0)
    return doc


# ---------------------------------------------------------------------------------------------
# MIS test scenes (tests/unit/test_mis.cpp): every kind of vertex the MIS weights must handle.

def rotation_to(direction):
    """Unit quaternion [x, y, z, w] turning a node's local -Z (the direction glTF lights and
    cameras point along) into `direction`."""
    a = (0.0, 0.0, -1.0)
    b = normalize(direction)
    c = dot(a, b)
    axis = cross(a, b)
    if dot(axis, axis) < 1e-24:
        return [0.0, 0.0, 0.0, 1.0] if c > 0 else [0.0, 1.0, 0.0, 0.0]
    axis = normalize(axis)
    half = 0.5 * math.acos(max(-1.0, min(1.0, c)))
    s = math.sin(half)
    return [num(axis[0] * s), num(axis[1] * s), num(axis[2] * s), num(math.cos(half))]


def material(name, base, metallic, roughness, extensions=None, emission=None):
    """A general metallic-roughness material (the scenes above use `lambert`)."""
    m = {
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [num(base[0]), num(base[1]), num(base[2]), 1.0],
            "metallicFactor": num(metallic),
            "roughnessFactor": num(roughness),
        },
        "doubleSided": False,
    }
    if extensions:
        m["extensions"] = extensions
    if emission is not None:
        strength = max(emission)
        m["emissiveFactor"] = [num(c / strength) for c in emission]
        m.setdefault("extensions", {})["KHR_materials_emissive_strength"] = {"emissiveStrength": num(strength)}
    return m


def box_mesh(name, mat, lo, hi, inward, index_type=UNSIGNED_INT, skip=()):
    """The six faces of the axis-aligned box [lo, hi] with flat normals, facing into the box
    (inward) or out of it. `skip` names faces to leave out, e.g. ("y-",) for no bottom."""
    mesh = Mesh(name, mat, index_type)
    for axis in range(3):
        for side, coord in (("-", lo[axis]), ("+", hi[axis])):
            if "xyz"[axis] + side in skip:
                continue
            u, v = [k for k in range(3) if k != axis]
            pts = []
            for a, b in ((lo[u], lo[v]), (hi[u], lo[v]), (hi[u], hi[v]), (lo[u], hi[v])):
                p = [0.0, 0.0, 0.0]
                p[axis], p[u], p[v] = coord, a, b
                pts.append(tuple(p))
            outward = [0.0, 0.0, 0.0]
            outward[axis] = -1.0 if side == "-" else 1.0
            facing = tuple(-c for c in outward) if inward else tuple(outward)
            mesh.flat_polygon(pts, facing)
    return mesh


def holed_rectangle(mesh, y, xs, zs, facing, hole=(1, 1)):
    """The rectangle xs[0]..xs[3] x zs[0]..zs[3] at height y as a 3x3 grid of quads (shared
    vertices, no T-junctions) without the cell `hole`; every quad faces along `facing` (+-y)."""
    grid = {}

    def vertex(i, j):
        if (i, j) not in grid:
            grid[(i, j)] = mesh.vertex((xs[i], y, zs[j]), (0.0, facing, 0.0))
        return grid[(i, j)]

    for j in range(3):
        for i in range(3):
            if (i, j) == hole:
                continue
            a, b, c, d = vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)
            # cross(b-a, c-a).y = -dx*dz < 0: (a, b, c) faces -y
            tris = ((a, b, c), (a, c, d)) if facing < 0 else ((a, c, b), (a, d, c))
            for tri in tris:
                p = [mesh.positions[k] for k in tri]
                assert cross(sub(p[1], p[0]), sub(p[2], p[0]))[1] * facing > 0
                mesh.triangles.append(tri)


def translated_icosphere_mesh(name, mat, level, radius, centre, index_type=UNSIGNED_INT):
    """Closed icosphere wound outward, shared vertices and smooth (radial) normals."""
    verts, faces = icosphere(level)
    mesh = Mesh(name, mat, index_type)
    for v in verts:
        mesh.vertex(add(centre, scale(v, radius)), v)
    for a, b, c in faces:
        mesh.triangles.append((a, b, c))
    return mesh


class PunctualDocument(Document):
    """A Document that may also hold spot and directional lights and materials with any of the
    implemented KHR material extensions (listed in extensionsUsed). Documents built by the
    scenes above are unaffected."""

    def __init__(self, description, analytic=None, analytic_params=None):
        Document.__init__(self, description, analytic, analytic_params)
        self.extra_lights = []

    def add_spot_light(self, name, position, direction, color, intensity, inner, outer):
        spot = {"innerConeAngle": num(inner), "outerConeAngle": num(outer)}
        self.extra_lights.append(({"name": name, "type": "spot", "color": [num(c) for c in color],
                                   "intensity": num(intensity), "spot": spot},
                                  [num(c) for c in position], rotation_to(direction)))

    def add_directional_light(self, name, direction, color, intensity):
        self.extra_lights.append(({"name": name, "type": "directional", "color": [num(c) for c in color],
                                   "intensity": num(intensity)}, None, rotation_to(direction)))

    def build(self):
        gltf, blob = Document.build(self)
        used = set(gltf["extensionsUsed"])
        for m in self.materials:
            used.update(m.get("extensions", {}).keys())
        if self.extra_lights:
            used.add("KHR_lights_punctual")
            lights = gltf.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})["lights"]
            for light, translation, rotation in self.extra_lights:
                lights.append(light)
                node = {"name": light["name"], "rotation": rotation,
                        "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}}
                if translation is not None:
                    node["translation"] = translation
                gltf["nodes"].append(node)
            gltf["scenes"][0]["nodes"] = list(range(len(gltf["nodes"])))
        gltf["extensionsUsed"] = sorted(used)
        return gltf, blob


MIS_ZOO_DIRECTIONAL = (-0.2, -1.0, -0.1)


def mis_zoo():
    doc = PunctualDocument(
        "MIS zoo: a closed room [-2,2]x[0,3]x[-2,2] (diffuse walls facing inward) with an opening "
        "x in [0,1], z in [-0.6,0.4] in the ceiling; a smooth mirror (metallic 1, roughness 0) in "
        "front of the left wall; a smooth glass sphere (transmission 1, roughness 0, ior 1.5, "
        "closed, wound outward, smooth normals) of radius 0.45 at (0.5,0.45,-0.3); a rough metal "
        "block (metallic 1, roughness 0.35); a small area light under the ceiling; a point light, a "
        "spot light and a directional light that shines through the opening onto the glass "
        "sphere and the floor; camera inside. A constant environment (given on the command line) "
        "also enters through the opening. For the MIS weight tests (every kind of vertex: delta "
        "reflection and refraction, glossy, diffuse, area/point/spot/directional/environment "
        "lights). No closed form.")
    wall = lambert("wall", (0.7, 0.7, 0.7))
    red = lambert("red_wall", (0.7, 0.15, 0.1))
    floor_mat = lambert("floor", (0.55, 0.6, 0.65))
    mirror = material("mirror", (0.95, 0.95, 0.95), 1.0, 0.0)
    glass = material("glass", (1.0, 1.0, 1.0), 0.0, 0.0,
                     {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                      "KHR_materials_ior": {"ior": 1.5}})
    rough_metal = material("rough_metal", (0.9, 0.7, 0.45), 1.0, 0.35)
    lamp_mat = lambert("lamp", (0.8, 0.8, 0.8), emission=(40.0, 36.0, 30.0))

    room = box_mesh("room", wall, (-2.0, 0.0, -2.0), (2.0, 3.0, 2.0), True, skip=("y-", "y+", "x+"))
    right = Mesh("right_wall", red, UNSIGNED_INT)
    right.flat_polygon([(2.0, 0.0, -2.0), (2.0, 0.0, 2.0), (2.0, 3.0, 2.0), (2.0, 3.0, -2.0)], (-1.0, 0.0, 0.0))
    floor = Mesh("floor", floor_mat, UNSIGNED_INT)
    floor.flat_polygon([(-2.0, 0.0, -2.0), (2.0, 0.0, -2.0), (2.0, 0.0, 2.0), (-2.0, 0.0, 2.0)], (0.0, 1.0, 0.0))
    ceiling = Mesh("ceiling", wall, UNSIGNED_INT)
    holed_rectangle(ceiling, 3.0, [-2.0, 0.0, 1.0, 2.0], [-2.0, -0.6, 0.4, 2.0], -1.0)
    mirror_mesh = Mesh("mirror", mirror, UNSIGNED_INT)
    mirror_mesh.flat_polygon([(-1.98, 0.4, -1.4), (-1.98, 0.4, 0.9), (-1.98, 2.3, 0.9), (-1.98, 2.3, -1.4)],
                             (1.0, 0.0, 0.0))
    sphere = translated_icosphere_mesh("glass_sphere", glass, 3, 0.45, (0.5, 0.45, -0.3))
    block = box_mesh("rough_metal_block", rough_metal, (-1.3, 0.0, -1.5), (-0.6, 0.7, -0.8), False, skip=("y-",))
    lamp = Mesh("lamp", lamp_mat, UNSIGNED_INT)
    lamp.flat_polygon([(-1.2, 2.98, -1.2), (-0.8, 2.98, -1.2), (-0.8, 2.98, -0.8), (-1.2, 2.98, -0.8)],
                      (0.0, -1.0, 0.0))
    for m in (room, right, floor, ceiling, mirror_mesh, sphere, block, lamp):
        doc.add_mesh(m)
    doc.add_point_light("point_light", (1.3, 2.2, 1.1), (1.0, 0.9, 0.8), 3.0)
    doc.add_spot_light("spot_light", (1.6, 2.6, -1.6), (-1.1, -2.15, 1.3), (0.8, 0.9, 1.0), 40.0, 0.25, 0.45)
    doc.add_directional_light("directional_light", MIS_ZOO_DIRECTIONAL, (1.0, 1.0, 0.95), 2.0)
    eye, target = (0.3, 1.4, 1.85), (-0.2, 0.9, -1.0)
    doc.set_camera("camera", eye, rotation_to(sub(target, eye)), math.radians(70.0))
    return doc


def white_box():
    rho = 0.999
    doc = Document(
        "Long paths: a closed cube [-1,1]^3 facing inward, pure Lambertian (specularFactor 0) of "
        "albedo 0.999, with a small emissive patch 0.2x0.2 at y=0.99 under the ceiling's centre "
        "(one-sided, facing down, radiance 1, albedo 0.999). Camera at the centre looking along -z, "
        "yfov 60 degrees. With Russian roulette on the throughput a subpath survives each bounce "
        "with probability 0.999, so paths of hundreds of vertices are common.",
        None, {"rho": rho})
    wall = lambert("white", (rho, rho, rho))
    patch_mat = lambert("patch", (rho, rho, rho), emission=(1.0, 1.0, 1.0))
    doc.add_mesh(box_mesh("box", wall, (-1.0, -1.0, -1.0), (1.0, 1.0, 1.0), True))
    patch = Mesh("patch", patch_mat, UNSIGNED_INT)
    patch.flat_polygon([(-0.1, 0.99, -0.1), (0.1, 0.99, -0.1), (0.1, 0.99, 0.1), (-0.1, 0.99, 0.1)], (0.0, -1.0, 0.0))
    doc.add_mesh(patch)
    doc.set_camera("camera", (0.0, 0.0, 0.0), [0.0, 0.0, 0.0, 1.0], math.radians(60.0))
    return doc


# ---------------------------------------------------------------------------------------------
# Benchmark scenes (bench/README.md): each stresses a different estimator or the traversal.

def emissive_sphere_material(name, radiance):
    """Black (non-reflecting) Lambertian sphere emitting white radiance `radiance`."""
    return lambert(name, (0.0, 0.0, 0.0), emission=(radiance, radiance, radiance))


VEACH_RADII = (0.05, 0.15, 0.4, 1.0)
VEACH_POWER_RADIANCE = 2.0  # radiance of the largest sphere; all four emit the same power
VEACH_ROUGHNESS = (0.1, 0.2, 0.35, 0.55)


def veach_mis():
    doc = Document(
        "Veach-style MIS scene: four glossy metal plates (metallic 1, base colour 0.8, roughness "
        "0.1, 0.2, 0.35, 0.55 from back to front) tilted so that each reflects the row of four "
        "spherical area lights towards the camera; the spheres have radii 0.05, 0.15, 0.4, 1.0 "
        "and equal power (radiance proportional to 1/r^2: 800, 88.9, 12.5, 2). A dark diffuse "
        "floor and back wall. BSDF sampling wins for small roughness and big lights, light "
        "sampling for large roughness and small lights. No closed form.")
    floor_mat = lambert("dark_floor", (0.2, 0.2, 0.2))
    cam, light_centre = (0.0, 2.0, 15.0), (0.0, 6.5, -1.0)
    floor = Mesh("floor", floor_mat, UNSIGNED_INT)
    floor.flat_polygon([(-10.0, -4.0, -6.0), (10.0, -4.0, -6.0), (10.0, -4.0, 10.0), (-10.0, -4.0, 10.0)], (0.0, 1.0, 0.0))
    back = Mesh("back_wall", floor_mat, UNSIGNED_INT)
    back.flat_polygon([(-10.0, -4.0, -6.0), (10.0, -4.0, -6.0), (10.0, 12.0, -6.0), (-10.0, 12.0, -6.0)], (0.0, 0.0, 1.0))
    doc.add_mesh(floor)
    doc.add_mesh(back)
    for i, rough in enumerate(VEACH_ROUGHNESS):
        mat = material("plate_%d" % i, (0.8, 0.8, 0.8), 1.0, rough)
        c = (0.0, 0.5 - 1.0 * i, 1.0 + 1.3 * i)
        n = normalize(add(normalize(sub(cam, c)), normalize(sub(light_centre, c))))
        t = normalize(cross(n, (1.0, 0.0, 0.0)))
        half_w, half_d = 4.0, 0.55
        pts = []
        for a, b in ((-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)):
            pts.append(add(add(c, (a * half_w, 0.0, 0.0)), scale(t, b * half_d)))
        plate = Mesh("plate_%d" % i, mat, UNSIGNED_INT)
        plate.flat_polygon(pts, n)
        doc.add_mesh(plate)
    big = VEACH_RADII[-1]
    for i, r in enumerate(VEACH_RADII):
        radiance = VEACH_POWER_RADIANCE * (big / r) ** 2
        centre = (-3.75 + 2.5 * i, 6.5, -1.0)
        doc.add_mesh(translated_icosphere_mesh("light_%d" % i, emissive_sphere_material("light_%d" % i, radiance),
                                               2, r, centre))
    doc.set_camera("camera", cam, rotation_to(sub((0.0, -1.0, 2.0), cam)), math.radians(35.0))
    return doc


def narrow_gap():
    doc = Document(
        "Light through a narrow gap: a closed room [-2,2]x[0,2.5]x[-2,2] (white Lambert 0.7, "
        "facing inward) split by a 0.1-thick wall at x in [-0.05,0.05] with a vertical slit "
        "z in [-0.05,0.05] from floor to ceiling. The only light (0.4x0.4 quad, radiance 50, "
        "facing down, just under the ceiling) is in the left half; the camera in the right half "
        "sees only surfaces lit through the slit. Light subpaths pass the slit easily, camera "
        "subpaths and next-event estimation rarely: BDPT should beat PT here. No closed form.")
    wall = lambert("white", (0.7, 0.7, 0.7))
    lamp_mat = lambert("lamp", (0.0, 0.0, 0.0), emission=(50.0, 50.0, 50.0))
    doc.add_mesh(box_mesh("room", wall, (-2.0, 0.0, -2.0), (2.0, 2.5, 2.0), True))
    part = Mesh("partition", wall, UNSIGNED_INT)
    g, h, d = 0.05, 2.5, 0.05  # slit half width, room height, wall half thickness
    for z0, z1 in ((-2.0, -g), (g, 2.0)):
        part.flat_polygon([(-d, 0.0, z0), (-d, 0.0, z1), (-d, h, z1), (-d, h, z0)], (-1.0, 0.0, 0.0))
        part.flat_polygon([(d, 0.0, z0), (d, 0.0, z1), (d, h, z1), (d, h, z0)], (1.0, 0.0, 0.0))
    for z, facing in ((-g, 1.0), (g, -1.0)):  # the slit's sides
        part.flat_polygon([(-d, 0.0, z), (d, 0.0, z), (d, h, z), (-d, h, z)], (0.0, 0.0, facing))
    doc.add_mesh(part)
    lamp = Mesh("lamp", lamp_mat, UNSIGNED_INT)
    lamp.flat_polygon([(-1.6, 2.48, -0.2), (-1.2, 2.48, -0.2), (-1.2, 2.48, 0.2), (-1.6, 2.48, 0.2)], (0.0, -1.0, 0.0))
    doc.add_mesh(lamp)
    eye = (1.9, 1.3, 1.9)
    doc.set_camera("camera", eye, rotation_to(sub((0.0, 0.7, -0.8), eye)), math.radians(70.0))
    return doc


def caustic_glass():
    doc = PunctualDocument(
        "Caustic: a smooth glass sphere (level-3 icosphere, smooth normals, radius 0.5, IOR 1.5, "
        "transmission 1) at (0,0.8,0) above a white Lambert floor (0.8) with a back wall, lit by a "
        "small bright area light (0.1x0.1 quad at y=3, radiance 2000, facing down). The sphere "
        "focuses the light into a caustic on the floor (a ball lens of focal length 0.75 from its "
        "centre), reachable only by light subpaths (L S S D E): light tracing and BDPT see it, "
        "PT only by hitting the small light through the glass. No closed form.")
    white = lambert("white", (0.8, 0.8, 0.8))
    glass = material("glass", (1.0, 1.0, 1.0), 0.0, 0.0,
                     {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                      "KHR_materials_ior": {"ior": 1.5}})
    lamp_mat = lambert("lamp", (0.0, 0.0, 0.0), emission=(2000.0, 2000.0, 2000.0))
    floor = Mesh("floor", white, UNSIGNED_INT)
    floor.flat_polygon([(-3.0, 0.0, -3.0), (3.0, 0.0, -3.0), (3.0, 0.0, 3.0), (-3.0, 0.0, 3.0)], (0.0, 1.0, 0.0))
    back = Mesh("back_wall", white, UNSIGNED_INT)
    back.flat_polygon([(-3.0, 0.0, -3.0), (3.0, 0.0, -3.0), (3.0, 4.0, -3.0), (-3.0, 4.0, -3.0)], (0.0, 0.0, 1.0))
    lamp = Mesh("lamp", lamp_mat, UNSIGNED_INT)
    lamp.flat_polygon([(0.05, 3.0, -0.05), (0.15, 3.0, -0.05), (0.15, 3.0, 0.05), (0.05, 3.0, 0.05)], (0.0, -1.0, 0.0))
    for m in (floor, back, translated_icosphere_mesh("glass_sphere", glass, 3, 0.5, (0.0, 0.8, 0.0)), lamp):
        doc.add_mesh(m)
    eye = (0.0, 2.2, 3.5)
    doc.set_camera("camera", eye, rotation_to(sub((0.0, 0.3, 0.0), eye)), math.radians(45.0))
    return doc


SPHERE_GRID_N = 14  # 14 x 14 = 196 instances


def sphere_grid(level):
    """196 instances of one icosphere mesh (nodes with translations): 196 * 20 * 4^level triangles."""
    tris = SPHERE_GRID_N * SPHERE_GRID_N * 20 * 4 ** level
    doc = Document(
        "Traversal-bound scene: one level-%d icosphere mesh (radius 0.45, smooth normals, grey "
        "Lambert 0.6) placed by %d nodes on a 14x14 grid with spacing 1 (the loader copies it per "
        "node: %d sphere triangles), on a white floor, lit by a 4x4 area light (radiance 5) at "
        "y=6 facing down. Camera looking down the grid at 40 degrees." % (level, SPHERE_GRID_N ** 2, tris))
    grey = lambert("grey", (0.6, 0.6, 0.6))
    white = lambert("white", (0.75, 0.75, 0.75))
    lamp_mat = lambert("lamp", (0.0, 0.0, 0.0), emission=(5.0, 5.0, 5.0))
    sphere = smooth_icosphere_mesh("sphere", grey, level, 0.45, False, UNSIGNED_INT)
    half = (SPHERE_GRID_N - 1) * 0.5
    sphere.instances = [(i - half, 0.45, j - half) for j in range(SPHERE_GRID_N) for i in range(SPHERE_GRID_N)]
    floor = Mesh("floor", white, UNSIGNED_INT)
    floor.flat_polygon([(-9.0, 0.0, -9.0), (9.0, 0.0, -9.0), (9.0, 0.0, 9.0), (-9.0, 0.0, 9.0)], (0.0, 1.0, 0.0))
    lamp = Mesh("lamp", lamp_mat, UNSIGNED_INT)
    lamp.flat_polygon([(-2.0, 6.0, -2.0), (2.0, 6.0, -2.0), (2.0, 6.0, 2.0), (-2.0, 6.0, 2.0)], (0.0, -1.0, 0.0))
    for m in (sphere, floor, lamp):
        doc.add_mesh(m)
    eye = (0.0, 9.0, 11.0)
    doc.set_camera("camera", eye, rotation_to(sub((0.0, 0.0, 0.5), eye)), math.radians(40.0))
    return doc


SPHERE_GRID_LEVEL = 4  # 196 * 5120 = 1003520 sphere triangles


def png_bytes(width, height, rows):
    """An 8-bit RGBA PNG (rows: height lists of width (r, g, b, a) tuples, top row first)."""
    import zlib
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rows)

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


GLTF_FEATURES_DESCRIPTION = (
    "glTF content features together (issue 13), units metres: a floor y=0 (x in [-3,3], z in "
    "[-1.5,3]) and a back wall z=-1.5 (x in [-3,3], y in [0,3.5]) filling the view; the floor is Lambert grey 0.6 with a normal map of stripes "
    "tilted about 20 degrees alternately towards +x and -x (8x8 texels, nearest); a vertical "
    "MASK cut-out quad (x in [-0.6,0.6], y in [0.1,1.1], z=0, double-sided, orange) whose 4x4 "
    "nearest alpha texture is a checkerboard (covered on half its area, cutoff 0.5); a BLEND quad "
    "(alpha 0.5, blue, double-sided) at x in [0.7,1.2], y in [0,0.8], z=-0.7; an area light facing "
    "down at y=1.8 (x,z in [-0.5,0.5]) whose emission is (6,6,6) times a 2x2 emissive texture "
    "(white, orange, black, white). Vertex colours (COLOR_0) tint the back wall from white at the "
    "bottom to light green at the top. Camera at (0,1,3.2) looking at (0,0.6,0), yfov 50 degrees. "
    "Reference-comparison scene (no closed form).")


def gltf_features():
    blob = bytearray()
    views, accessors, meshes, nodes = [], [], [], []

    def acc(values, ctype, fmt, count, kind, mm=False):
        while len(blob) % 4:
            blob.append(0)
        data = struct.pack("<" + fmt * (len(values) // len(fmt)), *values)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob.extend(data)
        a = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": kind}
        if mm:
            n = len(values) // count
            a["min"] = [min(f32(values[i * n + k]) for i in range(count)) for k in range(n)]
            a["max"] = [max(f32(values[i * n + k]) for i in range(count)) for k in range(n)]
        accessors.append(a)
        return len(accessors) - 1

    def quad(name, corners, normal, uvs, material, colors=None):
        pos = [c for p in corners for c in p]
        attrs = {"POSITION": acc(pos, FLOAT, "f", 4, "VEC3", True),
                 "NORMAL": acc(list(normal) * 4, FLOAT, "f", 4, "VEC3"),
                 "TEXCOORD_0": acc([c for uv in uvs for c in uv], FLOAT, "f", 4, "VEC2")}
        if colors is not None:
            attrs["COLOR_0"] = acc([c for col in colors for c in col], FLOAT, "f", 4, "VEC4")
        idx = acc([0, 1, 2, 0, 2, 3], UNSIGNED_SHORT, "H", 6, "SCALAR")
        meshes.append({"name": name, "primitives": [{"attributes": attrs, "indices": idx, "material": material}]})
        nodes.append({"name": name, "mesh": len(meshes) - 1})

    def encode(n):  # a unit normal in tangent space -> 8-bit texel
        return tuple(int(round((c * 0.5 + 0.5) * 255)) for c in n) + (255,)
    t = math.radians(20.0)
    left, right = encode((-math.sin(t), 0.0, math.cos(t))), encode((math.sin(t), 0.0, math.cos(t)))
    normal_rows = [[left if (x // 2) % 2 == 0 else right for x in range(8)] for _ in range(8)]
    alpha_rows = [[(255, 255, 255, 255 if (x + y) % 2 == 0 else 0) for x in range(4)] for y in range(4)]
    white, orange, black = (255, 255, 255, 255), (255, 160, 60, 255), (0, 0, 0, 255)
    emissive_rows = [[white, orange], [black, white]]
    images = [{"uri": "data:image/png;base64," + base64.b64encode(png_bytes(len(r[0]), len(r), r)).decode("ascii")}
              for r in (normal_rows, alpha_rows, emissive_rows)]
    samplers = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 10497, "wrapT": 10497}]
    textures = [{"source": i, "sampler": 0} for i in range(3)]
    spec0 = {"KHR_materials_specular": {"specularFactor": 0.0}}

    def lam(name, rgba, **extra):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": [num(c) for c in rgba], "metallicFactor": 0.0,
                                                   "roughnessFactor": 1.0},
             "extensions": dict(spec0)}
        m.update(extra)
        return m
    materials = [
        lam("bumpy_floor", (0.6, 0.6, 0.6, 1.0), normalTexture={"index": 0, "scale": 1.0}),
        lam("wall", (0.7, 0.7, 0.7, 1.0)),
        dict(lam("cutout", (0.9, 0.45, 0.15, 1.0), alphaMode="MASK", alphaCutoff=0.5, doubleSided=True),
             pbrMetallicRoughness={"baseColorFactor": [0.9, 0.45, 0.15, 1.0], "baseColorTexture": {"index": 1},
                                   "metallicFactor": 0.0, "roughnessFactor": 1.0}),
        lam("blend", (0.2, 0.3, 0.9, 0.5), alphaMode="BLEND", doubleSided=True),
        dict(lam("textured_light", (0.0, 0.0, 0.0, 1.0), emissiveFactor=[1.0, 1.0, 1.0], emissiveTexture={"index": 2}),
             extensions=dict(spec0, KHR_materials_emissive_strength={"emissiveStrength": 6.0})),
    ]
    quad("floor", [(-3, 0, 3), (3, 0, 3), (3, 0, -1.5), (-3, 0, -1.5)], (0, 1, 0),
         [(0, 1), (1, 1), (1, 0), (0, 0)], 0)
    quad("back_wall", [(-3, 0, -1.5), (3, 0, -1.5), (3, 3.5, -1.5), (-3, 3.5, -1.5)], (0, 0, 1),
         [(0, 1), (1, 1), (1, 0), (0, 0)], 1, colors=[(1, 1, 1, 1), (1, 1, 1, 1), (0.7, 1, 0.7, 1), (0.7, 1, 0.7, 1)])
    quad("cutout", [(-0.6, 0.1, 0), (0.6, 0.1, 0), (0.6, 1.1, 0), (-0.6, 1.1, 0)], (0, 0, 1),
         [(0, 1), (1, 1), (1, 0), (0, 0)], 2)
    quad("blend", [(0.7, 0, -0.7), (1.2, 0, -0.7), (1.2, 0.8, -0.7), (0.7, 0.8, -0.7)], (0, 0, 1),
         [(0, 1), (1, 1), (1, 0), (0, 0)], 3)
    quad("textured_light", [(-0.5, 1.8, -0.5), (0.5, 1.8, -0.5), (0.5, 1.8, 0.5), (-0.5, 1.8, 0.5)], (0, -1, 0),
         [(0, 0), (1, 0), (1, 1), (0, 1)], 4)
    eye, target = (0.0, 1.0, 3.2), (0.0, 0.6, 0.0)
    nodes.append({"name": "camera", "camera": 0, "translation": [num(c) for c in eye],
                  "rotation": rotation_to(sub(target, eye))})
    while len(blob) % 4:
        blob.append(0)
    gltf = {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "extensionsUsed": ["KHR_materials_emissive_strength", "KHR_materials_specular"],
        "materials": materials, "meshes": meshes, "accessors": accessors, "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode("ascii")}],
        "images": images, "samplers": samplers, "textures": textures,
        "cameras": [{"name": "camera", "type": "perspective",
                     "perspective": {"yfov": num(math.radians(50.0)), "aspectRatio": 1.0, "znear": 0.001}}],
        "nodes": nodes,
        "scenes": [{"name": "scene", "nodes": list(range(len(nodes))), "extras": {"description": GLTF_FEATURES_DESCRIPTION}}],
        "scene": 0,
    }
    with open(os.path.join(OUT_DIR, "gltf-features.gltf"), "wb") as f:
        f.write((dumps(gltf) + "\n").encode("ascii"))


# ---------------------------------------------------------------------------------------------
# Environment map scene: a small procedural HDR sky with a sun (Radiance .hdr, written here) and
# an outdoor arrangement lit only by it (render with --env-map scenes/env-map-sky.hdr).

ENV_SKY_WIDTH, ENV_SKY_HEIGHT = 128, 64
ENV_SUN = (1500.0, 1350.0, 1100.0)  # radiance of the sun texels


def env_sky_texel(col, row):
    """Linear RGB of texel (col, row) of the sky map: row 0 = +Y (docs/lights.md, "Environment")."""
    theta = math.pi * (row + 0.5) / ENV_SKY_HEIGHT
    phi = 2.0 * math.pi * (col + 0.5) / ENV_SKY_WIDTH - math.pi
    up = math.cos(theta)
    if 24 <= col <= 25 and 17 <= row <= 18:  # a 2x2-texel sun, about 37 degrees above the horizon
        return ENV_SUN
    if up < 0.0:
        return (0.10, 0.085, 0.07)  # dim ground
    horizon = math.exp(-8.0 * up)
    s = 0.25 + 0.75 * (1.0 - up) * (0.8 + 0.2 * math.cos(phi))
    return (0.30 * s + 0.5 * horizon, 0.45 * s + 0.45 * horizon, 0.85 * s + 0.35 * horizon)


def rgbe(rgb):
    """Radiance RGBE encoding of one linear RGB value (Greg Ward's float2rgbe)."""
    v = max(rgb)
    if v < 1e-32:
        return (0, 0, 0, 0)
    m, e = math.frexp(v)  # v = m * 2^e, m in [0.5, 1)
    f = m * 256.0 / v
    return (int(rgb[0] * f), int(rgb[1] * f), int(rgb[2] * f), e + 128)


def write_hdr(filename, width, height, texel):
    """A Radiance .hdr file with new-style run-length scanlines holding literal runs only (so
    no first pixel can be mistaken for a scanline header); rows top to bottom."""
    out = bytearray(b"#?RADIANCE\n# " + GENERATOR.encode() + b"\nFORMAT=32-bit_rle_rgbe\n\n")
    out += ("-Y %d +X %d\n" % (height, width)).encode()
    for row in range(height):
        pixels = [rgbe(texel(col, row)) for col in range(width)]
        out += bytes((2, 2, width >> 8, width & 255))
        for c in range(4):
            channel = [p[c] for p in pixels]
            for start in range(0, width, 128):
                chunk = channel[start:start + 128]
                out.append(len(chunk))
                out += bytes(chunk)
    with open(os.path.join(OUT_DIR, filename), "wb") as f:
        f.write(bytes(out))


def env_map_outdoor():
    doc = Document(
        "Outdoor scene for environment maps, lit only by --env-map scenes/env-map-sky.hdr (a "
        "128x64 procedural sky with a 2x2-texel sun of radiance (1500, 1350, 1100), written by "
        "this script): a Lambert floor slab [-4,4]x[-0.1,0]x[-4,4] (albedo 0.6), a blue Lambert "
        "box [-1.2,-0.2]x[0,1]x[-0.8,0.2], a rough gold-coloured metal box "
        "[0.4,1.2]x[0,0.6]x[-0.3,0.5] (roughness 0.4) and a grey Lambert sphere of radius 0.45 at "
        "(0.1,0.45,1.1). Camera at (0,3.2,4.2) looking at (0,0.3,0), yfov 45 degrees: the floor "
        "fills the frame, the sky is seen only in reflections.",
        "No closed form: compare estimators (PT, LT, BDPT agree per pixel).", {})
    doc.add_mesh(box_mesh("floor", lambert("floor", (0.6, 0.6, 0.6)), (-4.0, -0.1, -4.0), (4.0, 0.0, 4.0), False))
    doc.add_mesh(box_mesh("blue box", lambert("blue", (0.2, 0.35, 0.7)), (-1.2, 0.0, -0.8), (-0.2, 1.0, 0.2), False))
    doc.add_mesh(box_mesh("metal box", material("gold", (0.95, 0.75, 0.4), 1.0, 0.4), (0.4, 0.0, -0.3),
                          (1.2, 0.6, 0.5), False))
    doc.add_mesh(translated_icosphere_mesh("sphere", lambert("grey", (0.5, 0.5, 0.5)), 3, 0.45, (0.1, 0.45, 1.1)))
    eye = (0.0, 3.2, 4.2)
    doc.set_camera("camera", eye, rotation_to(sub((0.0, 0.3, 0.0), eye)), math.radians(45.0))
    return doc



# ---------------------------------------------------------------------------------------------
# Volume absorption (KHR_materials_volume, docs/materials.md "Volume absorption")

def absorbing_glass_material(name, roughness, color, distance, thickness):
    """Glass (transmission 1, IOR 1.5) enclosing a Beer-Lambert medium: light crossing `distance`
    keeps the fraction `color`. thicknessFactor (the object's size) is what a rasteriser would
    use; bdptref traces the real distance and ignores it (with a warning)."""
    return material(name, (1.0, 1.0, 1.0), 0.0, roughness,
                    {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                     "KHR_materials_ior": {"ior": 1.5},
                     "KHR_materials_volume": {"thicknessFactor": num(thickness),
                                              "attenuationColor": [num(c) for c in color],
                                              "attenuationDistance": num(distance)}})


ABSORBING_GLOW = (60.0, 60.0, 60.0)  # the radiance of the emissive cube inside the absorbing box
ABSORBING_GLOW_BOX = ((0.52, 0.52, -0.18), (0.68, 0.68, -0.02))  # the cube (inside [0.1,1.1]x[0.3,0.9]x[-0.6,0.4])


def absorbing_glass():
    doc = PunctualDocument(
        "Volume absorption (KHR_materials_volume): a white Lambert floor y = 0 (0.75, x and z in "
        "[-3,3]) and back wall z = -1.6 (0.7) under a one-sided area light facing down at y = 2.4 "
        "(x in [-1.2,1.2], z in [-1,0.6], radiance (8,7.6,7)), out of the camera's view. Left: a "
        "smooth glass sphere (level-3 icosphere, smooth normals, radius 0.5, centre (-0.65,0.52,0), "
        "IOR 1.5, transmission 1) filled with a red medium: attenuationColor (0.95,0.4,0.3), "
        "attenuationDistance 0.5, so a ray through its centre keeps (0.90,0.16,0.09). Right: a "
        "floating rough glass box [0.1,1.1]x[0.3,0.9]x[-0.6,0.4] (roughness 0.6, IOR 1.5) filled "
        "with a cyan medium: attenuationColor (0.25,0.7,0.85), attenuationDistance 0.6 (its height). "
        "Inside the box, touching nothing, a small closed emissive cube " +
        "x".join("[%g,%g]" % (ABSORBING_GLOW_BOX[0][k], ABSORBING_GLOW_BOX[1][k]) for k in range(3)) +
        " (black base, one-sided outward emission, radiance (" + ", ".join("%g" % c for c in ABSORBING_GLOW) + ")): every segment "
        "from it ends on the glass's back side, so next-event and connection segments to it lie in "
        "the medium. The camera sees the floor and wall through both objects and the cube's glow "
        "through the box's rough faces; both objects cast coloured shadows and caustics on the "
        "floor. thicknessFactor is set to each object's size (a rasteriser's "
        "estimate; the traced distance is used). Camera at (0,1.7,3.4) looking at (0.05,0.45,-0.1), "
        "yfov 40 degrees.",
        "No closed form: compare estimators (PT, LT, BDPT agree per pixel).", {})
    white = lambert("floor", (0.75, 0.75, 0.75))
    wall = lambert("wall", (0.7, 0.7, 0.7))
    lamp_mat = lambert("lamp", (0.5, 0.5, 0.5), emission=(8.0, 7.6, 7.0))
    floor = Mesh("floor", white, UNSIGNED_INT)
    floor.flat_polygon([(-3.0, 0.0, -3.0), (3.0, 0.0, -3.0), (3.0, 0.0, 3.0), (-3.0, 0.0, 3.0)], (0.0, 1.0, 0.0))
    back = Mesh("back_wall", wall, UNSIGNED_INT)
    back.flat_polygon([(-3.0, 0.0, -1.6), (3.0, 0.0, -1.6), (3.0, 3.0, -1.6), (-3.0, 3.0, -1.6)], (0.0, 0.0, 1.0))
    lamp = Mesh("lamp", lamp_mat, UNSIGNED_INT)
    lamp.flat_polygon([(-1.2, 2.4, -1.0), (1.2, 2.4, -1.0), (1.2, 2.4, 0.6), (-1.2, 2.4, 0.6)], (0.0, -1.0, 0.0))
    red = absorbing_glass_material("red_absorbing_glass", 0.0, (0.95, 0.4, 0.3), 0.5, 1.0)
    cyan = absorbing_glass_material("cyan_absorbing_rough_glass", 0.6, (0.25, 0.7, 0.85), 0.6, 0.6)
    sphere = translated_icosphere_mesh("red glass sphere", red, 3, 0.5, (-0.65, 0.52, 0.0))
    box = box_mesh("cyan rough glass box", cyan, (0.1, 0.3, -0.6), (1.1, 0.9, 0.4), False)
    # The light inside the medium: closed and outward-facing, so that every segment from it meets
    # the glass's back side and is absorbed (docs/materials.md, "Volume absorption": the rule sees
    # the two ends of a segment only, so nothing else may lie inside the box).
    glow_mat = lambert("glow", (0.0, 0.0, 0.0), emission=ABSORBING_GLOW)
    glow = box_mesh("glow inside the box", glow_mat, ABSORBING_GLOW_BOX[0], ABSORBING_GLOW_BOX[1], False)
    for m in (floor, back, lamp, sphere, box, glow):
        doc.add_mesh(m)
    eye = (0.0, 1.7, 3.4)
    doc.set_camera("camera", eye, rotation_to(sub((0.05, 0.45, -0.1), eye)), math.radians(40.0))
    return doc


def main():
    write_hdr("env-map-sky.hdr", ENV_SKY_WIDTH, ENV_SKY_HEIGHT, env_sky_texel)
    write_gltf(env_map_outdoor(), "env-map-outdoor.gltf")
    gltf_features()
    write_gltf(cornell_box(), "cornell-box.gltf")
    write_glb(cornell_box(), "cornell-box.glb")
    write_gltf(furnace_box(), "furnace-box.gltf")
    write_gltf(sphere_point_light(), "sphere-point-light.gltf")
    write_glb(env_sphere(), "env-sphere.glb")
    write_gltf(mis_zoo(), "mis-zoo.gltf")
    write_gltf(white_box(), "white-box.gltf")
    write_gltf(cornell_box(0.1, CORNELL_SMALL_LIGHT_DESCRIPTION), "cornell-small-light.gltf")
    write_gltf(veach_mis(), "veach-mis.gltf")
    write_gltf(narrow_gap(), "narrow-gap.gltf")
    write_gltf(caustic_glass(), "caustic-glass.gltf")
    write_glb(sphere_grid(SPHERE_GRID_LEVEL), "sphere-grid.glb")
    write_gltf(absorbing_glass(), "absorbing-glass.gltf")


if __name__ == "__main__":
    main()
