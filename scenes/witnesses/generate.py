#!/usr/bin/env python3
"""Witness scenes: closed-form answers that settle a difference between bdptref and another
renderer (docs/validating-a-gpu-port.md, "Witnesses: settling a difference"). Each scene's
`extras.analytic` says what it renders, independently of any renderer; tests/scenes/
test_witnesses.cpp holds bdptref to it.

    python3 scenes/witnesses/generate.py     # rewrites the scenes into this folder

Same conventions and deterministic output as scenes/generate.py, whose builders it uses.
Standard library only.
"""
import base64
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.dont_write_bytecode = True  # no __pycache__ in the repository
import generate as g  # noqa: E402  (scenes/generate.py)

g.OUT_DIR = HERE
g.GENERATOR = "bdptref scenes/witnesses/generate.py"

# The Cornell box's light, ceiling hole and left wall (scenes/generate.py, cornell_box), in its units.
CEILING_Y = 548.8
LIGHT_X = (213.0, 343.0)
LIGHT_Z = (227.0, 332.0)
ROOM_X = (0.0, 556.0)
ROOM_Z = (0.0, 559.2)
WALL_RHO = 0.5
# The orthographic view of the wall's top: y in [CEILING_Y - 2 YMAG, CEILING_Y], z centred on the light.
YMAG = 100.0
VIEW_Z = 279.5


def quad(name, mat, corners, facing):
    mesh = g.Mesh(name, mat, g.UNSIGNED_INT)
    mesh.flat_polygon(corners, facing)
    return mesh


def write(doc, filename, camera=None):
    gltf, blob = doc.build()
    if camera is not None:
        gltf["cameras"] = [camera]
    gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    with open(os.path.join(HERE, filename), "wb") as f:
        f.write((g.dumps(gltf) + "\n").encode("ascii"))


def light_in_ceiling(with_ceiling, unit=1.0):
    """The Cornell box's configuration at depth 1: a one-sided light coplanar with the ceiling,
    inside a hole of it, seen at grazing angles by the top of a wall. `unit` scales every length
    (1: the Cornell box's millimetre-like units; 0.001: metres): the closed form does not change."""
    name = ("hole-light-wall" if with_ceiling else "open-light-wall") + ("" if unit == 1.0 else "-m")
    u = unit
    what = ("inside a rectangular hole of a Lambert ceiling (a 3x3 grid of quads x splits 0, 213, 343, 556; "
            "z splits 0, 227, 332, 559.2; facing down) at the same height" if with_ceiling else
            "alone (no ceiling around it: the control for hole-light-wall.gltf)")
    units = ("" if unit == 1.0 else
             " Every length below is multiplied by %g (the same scene in metres: the image is the same, "
             "a renderer whose answer depends on the unit of length is wrong in one of them)." % unit)
    doc = g.Document(
        "Witness (docs/validating-a-gpu-port.md): the Cornell box's light in its hole, seen at grazing angles." + units +
        " A one-sided emissive quad x in [213,343], z in [227,332] at y = 548.8 facing down, radiance 1 "
        "(black base), " + what + ". A Lambert wall x = 0 (y in [0,548.8], z in [0,559.2], albedo 0.5, "
        "specularFactor 0) facing +x. An orthographic camera at (100, 448.8, 279.5) looking along -x, "
        "xmag = ymag = 100, sees the wall's top 200 units: the top rows see the light at grazing angles. "
        "Render at --max-depth 1 (direct light only).",
        "At --max-depth 1 a wall point p (normal +x) has radiance rho/pi * Le * sum_i theta_i (n . u_i)/2 "
        "over the light's edges (Lambert's polygon formula: theta_i the angle the edge v_i v_i+1 subtends at p, "
        "u_i the unit normal of the plane through p and the edge, oriented so that the sum is positive); "
        "a pixel is its mean over the pixel's footprint (the camera is orthographic, the wall facing it). "
        "Points at y = 548.8 see the light edge-on: 0.",
        {"rho": WALL_RHO, "Le": 1.0, "light_x": [c * u for c in LIGHT_X], "light_z": [c * u for c in LIGHT_Z],
         "light_y": CEILING_Y * u, "wall_x": 0.0, "ymag": YMAG * u,
         "camera": [100.0 * u, (CEILING_Y - YMAG) * u, VIEW_Z * u], "max_depth": 1})

    def P(x, y, z):
        return (x * u, y * u, z * u)

    wall = g.lambert("wall", (WALL_RHO, WALL_RHO, WALL_RHO))
    lamp = g.lambert("light", (0.0, 0.0, 0.0), emission=(1.0, 1.0, 1.0))
    doc.add_mesh(quad("wall", wall, [P(0.0, 0.0, ROOM_Z[0]), P(0.0, CEILING_Y, ROOM_Z[0]), P(0.0, CEILING_Y, ROOM_Z[1]),
                                     P(0.0, 0.0, ROOM_Z[1])], (1.0, 0.0, 0.0)))
    if with_ceiling:
        ceiling = g.Mesh("ceiling", g.lambert("ceiling", (WALL_RHO, WALL_RHO, WALL_RHO)), g.UNSIGNED_INT)
        g.holed_rectangle(ceiling, CEILING_Y * u, tuple(c * u for c in (ROOM_X[0], LIGHT_X[0], LIGHT_X[1], ROOM_X[1])),
                          tuple(c * u for c in (ROOM_Z[0], LIGHT_Z[0], LIGHT_Z[1], ROOM_Z[1])), -1.0)
        doc.add_mesh(ceiling)
    doc.add_mesh(quad("light", lamp, [P(LIGHT_X[0], CEILING_Y, LIGHT_Z[0]), P(LIGHT_X[1], CEILING_Y, LIGHT_Z[0]),
                                      P(LIGHT_X[1], CEILING_Y, LIGHT_Z[1]), P(LIGHT_X[0], CEILING_Y, LIGHT_Z[1])],
                      (0.0, -1.0, 0.0)))
    # looking along -x: local -Z -> world -X, a rotation of +90 degrees about +y
    s = math.sqrt(0.5)
    doc.set_camera("camera", P(100.0, CEILING_Y - YMAG, VIEW_Z), [0.0, g.num(s), 0.0, g.num(s)], 1.0)
    write(doc, name + ".gltf", {"name": "camera", "type": "orthographic",
                                "orthographic": {"xmag": YMAG * u, "ymag": YMAG * u, "znear": 0.001 * u,
                                                 "zfar": 1000.0 * u}})


def emitting_box(rho, name, description_extra):
    """A closed cube [-1,1]^3 facing inward, every face Lambert rho emitting Le = 1 one-sided."""
    doc = g.Document(
        "Witness (docs/validating-a-gpu-port.md): a closed cube [-1,1]^3, all six faces facing inward, "
        "each a Lambertian of albedo %g emitting radiance Le = 1 one-sided into the box. Camera at the centre "
        "looking along -z, yfov 60 degrees. %s" % (rho, description_extra),
        "Every pixel = Le*(1-rho^(N+1))/(1-rho) at maximum depth N (N scattering events).",
        {"rho": rho, "Le": 1.0})
    mat = g.lambert("emissive_white", (rho, rho, rho), emission=(1.0, 1.0, 1.0))
    doc.add_mesh(g.box_mesh("box", mat, (-1.0, -1.0, -1.0), (1.0, 1.0, 1.0), True))
    doc.set_camera("camera", (0.0, 0.0, 0.0), [0.0, 0.0, 0.0, 1.0], math.radians(60.0))
    write(doc, name + ".gltf")


def main():
    light_in_ceiling(True)
    light_in_ceiling(False)
    light_in_ceiling(True, 0.001)
    light_in_ceiling(False, 0.001)
    emitting_box(0.999, "white-emitting-box",
                 "white-box.gltf's albedo (0.999) with the light everywhere: long paths with a closed form.")


if __name__ == "__main__":
    main()
