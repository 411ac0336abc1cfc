#!/usr/bin/env python3
"""Scenes written for the conformance suite of `bdptref validate` (suite.json, docs/validate.md).

    python3 scenes/conformance/generate.py     # rewrites the scenes into this folder

Each covers terms of the estimator that the shipped scenes in scenes/ leave out (docs/validate.md,
"The suite: which scene covers which term"). Same conventions and deterministic output as
scenes/generate.py, whose builders it uses. Standard library only.
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
g.GENERATOR = "bdptref scenes/conformance/generate.py"


def quad(name, mat, corners, facing):
    mesh = g.Mesh(name, mat, g.UNSIGNED_INT)
    mesh.flat_polygon(corners, facing)
    return mesh


def floor_and_back_wall(doc, wall_albedo, wall_z, wall_top):
    """A Lambert floor y = 0 (0.6 grey, x and z in [-4,4]) and a back wall at z = wall_z facing +z."""
    floor_mat = g.lambert("floor", (0.6, 0.6, 0.6))
    wall = g.lambert("wall", wall_albedo)
    doc.add_mesh(quad("floor", floor_mat, [(-4.0, 0.0, -4.0), (4.0, 0.0, -4.0), (4.0, 0.0, 4.0), (-4.0, 0.0, 4.0)],
                      (0.0, 1.0, 0.0)))
    doc.add_mesh(quad("back wall", wall, [(-4.0, 0.0, wall_z), (4.0, 0.0, wall_z), (4.0, wall_top, wall_z),
                                          (-4.0, wall_top, wall_z)], (0.0, 0.0, 1.0)))


def downward_lamp(doc, y, xz, radiance):
    """A one-sided emissive quad at height y over the rectangle xz = ((x0, z0), (x1, z1)), facing down."""
    lamp = g.lambert("lamp", (0.5, 0.5, 0.5), emission=radiance)
    (x0, z0), (x1, z1) = xz
    doc.add_mesh(quad("lamp", lamp, [(x0, y, z0), (x1, y, z0), (x1, y, z1), (x0, y, z1)], (0.0, -1.0, 0.0)))


def lights_room():
    """Two-sided emission, spot lights filling the floor, one-sided emission and a very wide camera."""
    doc = g.PunctualDocument(
        "Conformance: emitters of every side and a wide camera. A closed Lambert room "
        "[-3,3]x[0,3]x[-3,3] (walls 0.7 white, floor 0.6 grey-blue, facing inward). A vertical "
        "double-sided emissive quad (radiance 4, doubleSided true: it emits from both faces) "
        "x in [-0.4,0.4], y in [1.2,2.2] at z = -1.5; a one-sided emissive quad (radiance 6) on the "
        "left wall (x = -2.99, y in [1,1.6], z in [0.5,1.5]) facing +x; two spot lights at "
        "(+-1.2, 2.9, -0.5) pointing straight down (intensity 40, inner/outer 0.35/0.6 rad) whose "
        "cones cover much of the floor. Camera at (0, 1.5, 2.8) looking at (0, 1.1, -1), yfov "
        "110 degrees: light tracing reaches it over the whole (very wide) field of view.",
        "No closed form: the suite's reference.", {})
    wall = g.lambert("wall", (0.7, 0.7, 0.7))
    floor_mat = g.lambert("floor", (0.5, 0.55, 0.65))
    doc.add_mesh(g.box_mesh("room", wall, (-3.0, 0.0, -3.0), (3.0, 3.0, 3.0), True, skip=("y-",)))
    doc.add_mesh(quad("floor", floor_mat, [(-3.0, 0.0, -3.0), (3.0, 0.0, -3.0), (3.0, 0.0, 3.0), (-3.0, 0.0, 3.0)],
                      (0.0, 1.0, 0.0)))
    two_sided = g.lambert("two_sided_lamp", (0.5, 0.5, 0.5), emission=(4.0, 3.6, 3.0), double_sided=True)
    doc.add_mesh(quad("two-sided lamp", two_sided,
                      [(-0.4, 1.2, -1.5), (0.4, 1.2, -1.5), (0.4, 2.2, -1.5), (-0.4, 2.2, -1.5)], (0.0, 0.0, 1.0)))
    one_sided = g.lambert("one_sided_lamp", (0.5, 0.5, 0.5), emission=(3.0, 4.5, 6.0))
    doc.add_mesh(quad("one-sided lamp", one_sided,
                      [(-2.99, 1.0, 0.5), (-2.99, 1.0, 1.5), (-2.99, 1.6, 1.5), (-2.99, 1.6, 0.5)], (1.0, 0.0, 0.0)))
    for x in (-1.2, 1.2):
        doc.add_spot_light("spot %+.1f" % x, (x, 2.9, -0.5), (0.0, -1.0, 0.0), (1.0, 0.95, 0.85), 40.0, 0.35, 0.6)
    eye = (0.0, 1.5, 2.8)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((0.0, 1.1, -1.0), eye)), math.radians(110.0))
    return doc


def glass_room(description, camera_in_glass):
    """A Lambert room; either the camera sits inside a closed glass box (rough metal floor), or a
    point light sits inside a closed glass sphere (Lambert floor)."""
    doc = g.PunctualDocument(description, "No closed form: the suite's reference.", {})
    wall = g.lambert("wall", (0.7, 0.7, 0.7))
    green = g.lambert("green", (0.2, 0.6, 0.25))
    doc.add_mesh(g.box_mesh("room", wall, (-2.0, 0.0, -2.0), (2.0, 2.5, 2.0), True, skip=("y-", "x-")))
    doc.add_mesh(quad("green wall", green, [(-2.0, 0.0, -2.0), (-2.0, 0.0, 2.0), (-2.0, 2.5, 2.0), (-2.0, 2.5, -2.0)],
                      (1.0, 0.0, 0.0)))
    # A rough metal floor seen through the glass; under the light in glass a Lambert floor (light
    # tracing's camera connections from a glossy floor are too noisy to test at the suite's budget).
    floor_mat = g.material("rough_floor", (0.85, 0.8, 0.7), 1.0, 0.3) if camera_in_glass else g.lambert("floor", (0.6, 0.6, 0.55))
    doc.add_mesh(quad("floor", floor_mat, [(-2.0, 0.0, -2.0), (2.0, 0.0, -2.0), (2.0, 0.0, 2.0), (-2.0, 0.0, 2.0)],
                      (0.0, 1.0, 0.0)))
    glass = g.material("glass", (1.0, 1.0, 1.0), 0.0, 0.0,
                       {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.5}})
    doc.add_mesh(g.box_mesh("block", g.lambert("block", (0.6, 0.45, 0.3)), (-1.2, 0.0, -1.4), (-0.4, 0.9, -0.6), False))
    if camera_in_glass:
        lamp = g.lambert("lamp", (0.5, 0.5, 0.5), emission=(12.0, 11.0, 9.0))
        doc.add_mesh(quad("lamp", lamp, [(-0.5, 2.49, -0.5), (0.5, 2.49, -0.5), (0.5, 2.49, 0.5), (-0.5, 2.49, 0.5)],
                          (0.0, -1.0, 0.0)))
        doc.add_mesh(g.box_mesh("glass box", glass, (-0.35, 0.9, 1.15), (0.35, 1.6, 1.85), False))
        eye = (0.0, 1.3, 1.5)
        doc.set_camera("camera", eye, g.rotation_to(g.sub((-0.2, 0.6, -1.0), eye)), math.radians(60.0))
    else:
        # The sphere is behind the camera: a pinhole camera never sees the glass, so light tracing
        # samples every path too.
        doc.add_mesh(g.translated_icosphere_mesh("glass sphere", glass, 3, 0.35, (1.2, 1.6, 1.3)))
        doc.add_point_light("light in glass", (1.2, 1.6, 1.3), (1.0, 0.9, 0.75), 6.0)
        eye = (0.3, 1.3, 1.2)
        doc.set_camera("camera", eye, g.rotation_to(g.sub((-1.0, 0.6, -1.0), eye)), math.radians(65.0))
    return doc


# (roughness G, metallic B) of the panel's 4 x 4 cells: G and B differ in every cell, so reading
# one channel for the other changes every cell; roughness stays >= 0.35 (light tracing's camera
# connections from the panel stay testable at the suite's budget).
ORTHO_PANEL_CELLS = [(90, 255), (230, 0), (150, 255), (115, 40)]


def ortho_rough_glass():
    """An orthographic camera over a Lambert floor: a floating rough glass slab and a panel whose
    metallic and roughness come from a metallicRoughnessTexture, under a large area light."""
    doc = g.PunctualDocument(
        "Conformance: rough transmission, a metallic-roughness texture and an orthographic camera. "
        "A Lambert floor y = 0 (0.6 grey, x in [-4,4], z in [-4,4]) and back wall z = -2.5 (0.7 white); a "
        "one-sided area light facing down at y = 2.2 (x in [-1.6,1.8], z in [-2.45,-0.8], radiance (6,5.7,5.1)), "
        "out of the camera's view. "
        "A closed rough glass slab [-1.85,-0.1]x[0.45,0.8]x[-0.9,1.1] floating above the floor "
        "(transmission 1, IOR 1.5, roughness 0.35): the camera sees the floor through two rough "
        "interfaces, and light reaches the floor under it through them. A panel at y = 0.02 "
        "(x in [0.1,1.85], z in [-0.9,1.2]; base colour (0.95,0.75,0.45), metallicFactor 1, "
        "roughnessFactor 1) with a 4x4 nearest metallicRoughnessTexture whose cells cycle through "
        "(roughness G, metallic B) = (90,255), (230,0), (150,255), (115,40) / 255: its mirror "
        "direction from the camera meets the light. Orthographic camera (xmag = ymag = 1.9) looking "
        "along (0,-1.2,-1) at (0,0.3,0.1) from 8 m away.",
        "No closed form: the suite's reference.", {})
    floor_and_back_wall(doc, (0.7, 0.7, 0.7), -2.5, 4.0)
    downward_lamp(doc, 2.2, ((-1.6, -2.45), (1.8, -0.8)), (6.0, 5.7, 5.1))
    glass = g.material("rough_glass", (1.0, 1.0, 1.0), 0.0, 0.35,
                       {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.5}})
    doc.add_mesh(g.box_mesh("rough glass slab", glass, (-1.85, 0.45, -0.9), (-0.1, 0.8, 1.1), False))
    panel_mat = g.material("textured_metal_rough", (0.95, 0.75, 0.45), 1.0, 1.0)
    panel_mat["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {"index": 0}
    panel = quad("panel", panel_mat, [(0.1, 0.02, -0.9), (1.85, 0.02, -0.9), (1.85, 0.02, 1.2), (0.1, 0.02, 1.2)],
                 (0.0, 1.0, 0.0))
    panel.uvs = [((x - 0.1) / 1.75, (z + 0.9) / 2.1) for x, _, z in panel.positions]
    doc.add_mesh(panel)
    forward = g.normalize((0.0, -1.2, -1.0))
    eye = g.sub((0.0, 0.3, 0.1), g.scale(forward, 8.0))
    doc.set_camera("camera", eye, g.rotation_to(forward), 1.0)
    gltf, blob = doc.build()
    gltf["cameras"] = [{"name": "camera", "type": "orthographic",
                        "orthographic": {"xmag": 1.9, "ymag": 1.9, "znear": 0.001, "zfar": 100.0}}]
    cells = ORTHO_PANEL_CELLS
    rows = [[(255,) + cells[(x + 2 * y) % 4] + (255,) for x in range(4)] for y in range(4)]
    gltf["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(g.png_bytes(4, 4, rows)).decode("ascii")}]
    gltf["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 10497, "wrapT": 10497}]
    gltf["textures"] = [{"source": 0, "sampler": 0}]
    gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    with open(os.path.join(HERE, "ortho-rough-glass.gltf"), "wb") as f:
        f.write((g.dumps(gltf) + "\n").encode("ascii"))


def layered_materials():
    """A clearcoat-covered floor and three large spheres (rough coats over Lambert and over rough
    gold, a sheen over dark Lambert) before a wall, under a large area light. The coats are rough
    so that light tracing renders every pixel (it cannot see a delta coat's reflection)."""
    doc = g.PunctualDocument(
        "Conformance: the KHR_materials_clearcoat and KHR_materials_sheen layers. A floor y = 0 "
        "(x, z in [-4,4]; grey Lambert 0.45 under a clearcoat 1.0 of roughness 0.3) and a back wall "
        "z = -2 (0.6 Lambert); a one-sided area light facing down at y = 2.6 (x in [-1.5,1.5], z in "
        "[-1.2,0.6], radiance (7,6.6,6)), out of the camera's view. Three smooth-shaded spheres of "
        "radius 0.62 at y = 0.62: left (x = -1.35) a red Lambert base under a clearcoat 1.0 of roughness "
        "0.15; middle (x = 0, z = -0.3) rough gold (metallic 1, roughness 0.5) under a clearcoat 0.9 "
        "of roughness 0.25; right (x = 1.35) a velvet: dark blue Lambert under a sheen of colour (0.95, 0.7, "
        "0.85) and roughness 0.35, lit from behind so that its grazing rim shows. Camera at (0, 1.55, 3.3) "
        "looking at (0, 0.5, -0.2), yfov 55 degrees.",
        "No closed form: the suite's reference.", {})
    spec0 = {"KHR_materials_specular": {"specularFactor": 0.0}}
    floor_mat = g.material("coated_floor", (0.45, 0.45, 0.45), 0.0, 1.0,
                           dict(spec0, KHR_materials_clearcoat={"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.3}))
    wall = g.lambert("wall", (0.6, 0.6, 0.6))
    doc.add_mesh(quad("floor", floor_mat, [(-4.0, 0.0, -4.0), (4.0, 0.0, -4.0), (4.0, 0.0, 4.0), (-4.0, 0.0, 4.0)],
                      (0.0, 1.0, 0.0)))
    doc.add_mesh(quad("back wall", wall, [(-4.0, 0.0, -2.0), (4.0, 0.0, -2.0), (4.0, 4.0, -2.0), (-4.0, 4.0, -2.0)],
                      (0.0, 0.0, 1.0)))
    downward_lamp(doc, 2.6, ((-1.5, -1.2), (1.5, 0.6)), (7.0, 6.6, 6.0))
    red = g.material("red_rough_coat", (0.75, 0.12, 0.08), 0.0, 1.0,
                     dict(spec0, KHR_materials_clearcoat={"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.15}))
    gold = g.material("gold_coat", (0.95, 0.72, 0.38), 1.0, 0.5,
                      {"KHR_materials_clearcoat": {"clearcoatFactor": 0.9, "clearcoatRoughnessFactor": 0.25}})
    velvet = g.material("velvet", (0.04, 0.06, 0.25), 0.0, 1.0,
                        dict(spec0, KHR_materials_sheen={"sheenColorFactor": [0.95, 0.7, 0.85], "sheenRoughnessFactor": 0.35}))
    for name, mat, centre in (("rough coat sphere", red, (-1.35, 0.62, 0.0)), ("coated gold sphere", gold, (0.0, 0.62, -0.3)),
                              ("sheen sphere", velvet, (1.35, 0.62, 0.0))):
        doc.add_mesh(g.translated_icosphere_mesh(name, mat, 3, 0.62, centre))
    eye = (0.0, 1.55, 3.3)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((0.0, 0.5, -0.2), eye)), math.radians(55.0))
    return doc


def sun_courtyard():
    """A directional light (the sun) for every estimator, path tracing included."""
    doc = g.PunctualDocument(
        "Conformance: a directional light for every estimator. An open Lambert courtyard: a floor "
        "[-3,3]x[-3,3] at y = 0 (0.6, 0.6, 0.55), a back wall z = -2.5, x in [-3,3], y in [0,2.6] facing +z "
        "(0.7, 0.5, 0.4), a block [-0.6,0.6]x[0,1.2]x[-0.8,0.4] (0.75) casting a shadow; one directional "
        "light (the sun, irradiance 3 W/m^2 on a surface facing it, colour (1, 0.97, 0.9)) shining along "
        "(0.45, -0.75, -0.5): direct light is next-event estimation of a delta light for path tracing, "
        "and emission sampling from the disk that bounds the scene for light tracing and BDPT. The "
        "camera at (0, 2.2, 3.2) looks at (0, 0.4, -0.8), yfov 50 degrees: every pixel sees the floor, "
        "the wall or the block, and the shadow is lit only by interreflection.",
        "No closed form: the suite's reference.", {})
    floor_mat = g.lambert("floor", (0.6, 0.6, 0.55))
    wall = g.lambert("wall", (0.7, 0.5, 0.4))
    block = g.lambert("block", (0.75, 0.75, 0.75))
    doc.add_mesh(quad("floor", floor_mat, [(-3.0, 0.0, -3.0), (3.0, 0.0, -3.0), (3.0, 0.0, 3.0), (-3.0, 0.0, 3.0)],
                      (0.0, 1.0, 0.0)))
    doc.add_mesh(quad("back wall", wall, [(-3.0, 0.0, -2.5), (3.0, 0.0, -2.5), (3.0, 2.6, -2.5), (-3.0, 2.6, -2.5)],
                      (0.0, 0.0, 1.0)))
    doc.add_mesh(g.box_mesh("block", block, (-0.6, 0.0, -0.8), (0.6, 1.2, 0.4), False, skip=("y-",)))
    doc.add_directional_light("sun", (0.45, -0.75, -0.5), (1.0, 0.97, 0.9), 3.0)
    eye = (0.0, 2.2, 3.2)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((0.0, 0.4, -0.8), eye)), math.radians(50.0))
    return doc


def lobe_box():
    """A closed room of two-lobe materials where roulette acts from the third vertex on: every
    bounce chooses a lobe and, past depth 2, decides survival with a probability below 1."""
    doc = g.PunctualDocument(
        "Conformance: lobe choice and Russian roulette at every deep vertex. A closed room "
        "[-1.5,1.5]x[0,2.4]x[-1.5,1.5] whose walls, floor and ceiling are glTF dielectrics (metallic 0, "
        "roughness 0.45: a diffuse lobe and a GGX specular lobe chosen per bounce) of base colours "
        "0.55 grey (walls, ceiling), (0.6, 0.35, 0.25) (floor) and (0.25, 0.45, 0.6) (the wall at x = -1.5), "
        "and a rough gold block (metallic 1, roughness 0.35) [0.2,0.9]x[0,0.8]x[-0.9,-0.2]; a one-sided "
        "area light (0.8 x 0.8, radiance (9, 8.5, 8)) under the ceiling. Throughput falls below 1 after "
        "a bounce or two, so roulette decides at most deep vertices of both subpaths, right after the "
        "lobe choice: decisions that would be correlated if they read one random number. Camera at "
        "(0, 1.2, 1.45) looking at (-0.2, 0.7, -1.5), yfov 70 degrees.",
        "No closed form: the suite's reference.", {})
    walls = g.material("plastic_walls", (0.55, 0.55, 0.55), 0.0, 0.45)
    floor_mat = g.material("plastic_floor", (0.6, 0.35, 0.25), 0.0, 0.45)
    blue = g.material("plastic_blue", (0.25, 0.45, 0.6), 0.0, 0.45)
    gold = g.material("rough_gold", (0.95, 0.72, 0.38), 1.0, 0.35)
    doc.add_mesh(g.box_mesh("room", walls, (-1.5, 0.0, -1.5), (1.5, 2.4, 1.5), True, skip=("y-", "x-")))
    doc.add_mesh(quad("floor", floor_mat, [(-1.5, 0.0, -1.5), (1.5, 0.0, -1.5), (1.5, 0.0, 1.5), (-1.5, 0.0, 1.5)],
                      (0.0, 1.0, 0.0)))
    doc.add_mesh(quad("blue wall", blue, [(-1.5, 0.0, -1.5), (-1.5, 0.0, 1.5), (-1.5, 2.4, 1.5), (-1.5, 2.4, -1.5)],
                      (1.0, 0.0, 0.0)))
    doc.add_mesh(g.box_mesh("gold block", gold, (0.2, 0.0, -0.9), (0.9, 0.8, -0.2), False, skip=("y-",)))
    downward_lamp(doc, 2.39, ((-0.4, -0.4), (0.4, 0.4)), (9.0, 8.5, 8.0))
    eye = (0.0, 1.2, 1.45)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((-0.2, 0.7, -1.5), eye)), math.radians(70.0))
    return doc


# ---- term-isolating scenes: each holds one feature of a busier scene above, alone ----------------

def lit_floor_and_wall(doc, lamp_y=2.6, lamp_xz=((-1.5, -1.2), (1.5, 0.6)), radiance=(7.0, 6.6, 6.0)):
    """A Lambert floor y = 0 (0.6), a back wall z = -2 (0.65, 6 m tall) and a one-sided area light facing down."""
    floor_and_back_wall(doc, (0.65, 0.65, 0.65), -2.0, 6.0)
    downward_lamp(doc, lamp_y, lamp_xz, radiance)


def sheen_sphere():
    """The velvet of layered-materials alone: a sheen without a clearcoat anywhere in the scene."""
    doc = g.PunctualDocument(
        "Conformance: KHR_materials_sheen alone (the velvet sphere of layered-materials.gltf without "
        "its clearcoats, so that a sheen term and a clearcoat term fail different scenes). A Lambert "
        "floor y = 0 (0.6) and back wall z = -2 (0.65), a one-sided area light facing down at y = 2.6 "
        "(x in [-1.5,1.5], z in [-1.2,0.6], radiance (7,6.6,6)) out of the camera's view, and one "
        "smooth-shaded sphere of radius 0.85 at (0, 0.85, -0.2) filling much of the frame: dark blue "
        "Lambert (0.04, 0.06, 0.25) under a sheen of colour (0.95, 0.7, 0.85) and roughness 0.35, whose "
        "grazing rim shows. Camera at (0, 1.3, 3.0) looking at (0, 0.65, -0.3), yfov 45 degrees.",
        "No closed form: the suite's reference.", {})
    lit_floor_and_wall(doc)
    velvet = g.material("velvet", (0.04, 0.06, 0.25), 0.0, 1.0,
                        {"KHR_materials_specular": {"specularFactor": 0.0},
                         "KHR_materials_sheen": {"sheenColorFactor": [0.95, 0.7, 0.85], "sheenRoughnessFactor": 0.35}})
    doc.add_mesh(g.translated_icosphere_mesh("sheen sphere", velvet, 3, 0.85, (0.0, 0.85, -0.2)))
    eye = (0.0, 1.3, 3.0)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((0.0, 0.65, -0.3), eye)), math.radians(45.0))
    return doc


def alpha_cutouts():
    """Alpha MASK and BLEND without textures (constant alpha), so that an alpha error and a texture
    error fail different scenes; the quads shadow the floor, so shadow rays must honour alpha."""
    doc = g.PunctualDocument(
        "Conformance: alpha MASK and BLEND alone, without textures (the alpha is baseColorFactor's). "
        "A Lambert floor y = 0 (0.6) and back wall z = -2 (0.65), a one-sided area light facing down "
        "at y = 2.6 (x in [-0.5,0.5], z in [-0.6,0.2], radiance (30,28.5,27)) out of the camera's view, small so that the quads' shadows are sharp. Three "
        "double-sided quads between the light and the floor: a horizontal MASK quad of alpha 0.3 "
        "(under its cutoff 0.5: fully cut out, it must neither be seen nor cast a shadow) at y = 1.3, "
        "x in [-1.6,-0.2], z in [-1.2,0.4]; a vertical MASK quad of alpha 0.8 (over the cutoff: opaque, "
        "orange) at z = -0.6, x in [-0.1,0.7], y in [0,0.9]; a horizontal BLEND quad of alpha 0.4 "
        "(blue: stochastic transparency, 60% of rays pass) at y = 0.7, x in [0.2,1.2], z in [-0.9,0.1]. "
        "Camera at (0, 2.0, 3.2) looking at (0, 0.4, -0.4), yfov 55 degrees.",
        "No closed form: the suite's reference.", {})
    lit_floor_and_wall(doc, lamp_xz=((-0.5, -0.6), (0.5, 0.2)), radiance=(30.0, 28.5, 27.0))

    def alpha_material(name, rgb, alpha, mode):
        m = g.lambert(name, rgb, double_sided=True)
        m["pbrMetallicRoughness"]["baseColorFactor"][3] = g.num(alpha)
        m["alphaMode"] = mode
        if mode == "MASK":
            m["alphaCutoff"] = 0.5
        return m
    cut = alpha_material("mask_cut_out", (0.2, 0.8, 0.2), 0.3, "MASK")
    opaque = alpha_material("mask_opaque", (0.9, 0.45, 0.15), 0.8, "MASK")
    blend = alpha_material("blend", (0.2, 0.3, 0.9), 0.4, "BLEND")
    doc.add_mesh(quad("cut-out quad", cut, [(-1.6, 1.3, -1.2), (-0.2, 1.3, -1.2), (-0.2, 1.3, 0.4), (-1.6, 1.3, 0.4)],
                      (0.0, 1.0, 0.0)))
    doc.add_mesh(quad("opaque mask quad", opaque, [(-0.1, 0.0, -0.6), (0.7, 0.0, -0.6), (0.7, 0.9, -0.6), (-0.1, 0.9, -0.6)],
                      (0.0, 0.0, 1.0)))
    doc.add_mesh(quad("blend quad", blend, [(0.2, 0.7, -0.9), (1.2, 0.7, -0.9), (1.2, 0.7, 0.1), (0.2, 0.7, 0.1)],
                      (0.0, 1.0, 0.0)))
    eye = (0.0, 2.0, 3.2)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((0.0, 0.4, -0.4), eye)), math.radians(55.0))
    return doc


def ortho_camera():
    """The orthographic camera of ortho-rough-glass over plain Lambert geometry: a camera error and
    a glass or texture error fail different scenes."""
    doc = g.PunctualDocument(
        "Conformance: an orthographic camera alone (that of ortho-rough-glass.gltf without its rough "
        "glass and textured panel). A Lambert floor y = 0 (0.6) and back wall z = -2 (0.65), a one-sided "
        "area light facing down at y = 2.4 (x in [1.9,3.1], z in [-1.2,0.4], radiance (12,11.4,10.8)) to the "
        "right of the camera's view (an orthographic camera looking down would see its dark back), and two Lambert blocks: [-1.3,-0.5]x[0,0.8]x[-0.9,-0.1] (0.75, 0.4, 0.3) and "
        "[0.3,1.1]x[0,0.5]x[-0.2,0.6] (0.3, 0.5, 0.75). Orthographic camera (xmag = ymag = 1.7, half "
        "extents) looking along (0,-1,-1) at (0,0.3,-0.3) from 8 m away.",
        "No closed form: the suite's reference.", {})
    lit_floor_and_wall(doc, lamp_y=2.4, lamp_xz=((1.9, -1.2), (3.1, 0.4)), radiance=(12.0, 11.4, 10.8))
    doc.add_mesh(g.box_mesh("red block", g.lambert("red", (0.75, 0.4, 0.3)), (-1.3, 0.0, -0.9), (-0.5, 0.8, -0.1), False,
                            skip=("y-",)))
    doc.add_mesh(g.box_mesh("blue block", g.lambert("blue", (0.3, 0.5, 0.75)), (0.3, 0.0, -0.2), (1.1, 0.5, 0.6), False,
                            skip=("y-",)))
    forward = g.normalize((0.0, -1.0, -1.0))
    eye = g.sub((0.0, 0.3, -0.3), g.scale(forward, 8.0))
    doc.set_camera("camera", eye, g.rotation_to(forward), 1.0)
    gltf, blob = doc.build()
    gltf["cameras"] = [{"name": "camera", "type": "orthographic",
                        "orthographic": {"xmag": 1.7, "ymag": 1.7, "znear": 0.001, "zfar": 100.0}}]
    gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    with open(os.path.join(HERE, "ortho-camera.gltf"), "wb") as f:
        f.write((g.dumps(gltf) + "\n").encode("ascii"))


def mirror_room():
    """A smooth metal mirror in a Lambert room: delta reflection without a dielectric, so that a
    delta-lobe error and a glass (Fresnel, eta) error fail different scenes."""
    doc = g.PunctualDocument(
        "Conformance: delta reflection alone, a smooth metal mirror (the delta lobes of camera-in-glass "
        "and mis-zoo without their glass). A closed Lambert room [-1.5,1.5]x[0,2.4]x[-1.5,1.5] (walls and "
        "ceiling 0.65, floor (0.6, 0.5, 0.4), the wall at x = -1.5 red (0.7, 0.2, 0.15), the wall at x = 1.5 "
        "green (0.2, 0.6, 0.25)), a Lambert block [0.3,1.0]x[0,0.9]x[0.1,0.8] (0.7, 0.7, 0.75), and a mirror "
        "on the back wall: x in [-1.2,1.2], y in [0.2,2.1] at z = -1.49 facing +z, metallic 1, roughness 0, "
        "base colour (0.95, 0.93, 0.9), filling most of the frame. The light is a one-sided strip (x in "
        "[-0.8,0.8], y in [2.16,2.36], radiance (14, 13.3, 12.5)) on the back wall above the mirror, 5 mm "
        "behind the mirror's plane and facing +z: no light reaches the mirror before a diffuse bounce, so "
        "the mirror throws no caustic (a path tracer's caustic is too heavy-tailed to test at the budget: "
        "a first version with the light under the ceiling flagged a clean path tracer on one pixel). "
        "Camera at (0.4, 1.3, 1.4) looking at (-0.1, 1.0, -1.5), yfov 60 degrees: most pixels see the "
        "room in the mirror (one delta bounce first).",
        "No closed form: the suite's reference.", {})
    walls = g.lambert("walls", (0.65, 0.65, 0.65))
    doc.add_mesh(g.box_mesh("room", walls, (-1.5, 0.0, -1.5), (1.5, 2.4, 1.5), True, skip=("y-", "x-", "x+")))
    for name, rgb, corners, facing in (
            ("floor", (0.6, 0.5, 0.4), [(-1.5, 0.0, -1.5), (1.5, 0.0, -1.5), (1.5, 0.0, 1.5), (-1.5, 0.0, 1.5)], (0.0, 1.0, 0.0)),
            ("red wall", (0.7, 0.2, 0.15), [(-1.5, 0.0, -1.5), (-1.5, 0.0, 1.5), (-1.5, 2.4, 1.5), (-1.5, 2.4, -1.5)], (1.0, 0.0, 0.0)),
            ("green wall", (0.2, 0.6, 0.25), [(1.5, 0.0, -1.5), (1.5, 0.0, 1.5), (1.5, 2.4, 1.5), (1.5, 2.4, -1.5)], (-1.0, 0.0, 0.0))):
        doc.add_mesh(quad(name, g.lambert(name.replace(" ", "_"), rgb), corners, facing))
    doc.add_mesh(g.box_mesh("block", g.lambert("block", (0.7, 0.7, 0.75)), (0.3, 0.0, 0.1), (1.0, 0.9, 0.8), False,
                            skip=("y-",)))
    lamp = g.lambert("lamp", (0.5, 0.5, 0.5), emission=(14.0, 13.3, 12.5))
    doc.add_mesh(quad("lamp", lamp, [(-0.8, 2.16, -1.495), (0.8, 2.16, -1.495), (0.8, 2.36, -1.495), (-0.8, 2.36, -1.495)],
                      (0.0, 0.0, 1.0)))
    mirror = g.material("mirror", (0.95, 0.93, 0.9), 1.0, 0.0)
    doc.add_mesh(quad("mirror", mirror, [(-1.2, 0.2, -1.49), (1.2, 0.2, -1.49), (1.2, 2.1, -1.49), (-1.2, 2.1, -1.49)],
                      (0.0, 0.0, 1.0)))
    eye = (0.4, 1.3, 1.4)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((-0.1, 1.0, -1.5), eye)), math.radians(60.0))
    return doc


def glossy_point_light():
    """GGX's value alone: a rough metal ball under a point light in a black void. Every path is
    camera -> ball -> light (depth 1; the ball is convex, so nothing it reflects comes back), which
    next-event estimation and light tracing evaluate and no BSDF sample carries: a GGX value error
    fails it, a GGX sampling or density error (VNDF, lobe choice) does not."""
    doc = g.PunctualDocument(
        "Conformance: the GGX BRDF's value alone. A flat-shaded level-4 icosphere of radius 0.9 at the "
        "origin (flat facets: no shading normals), metallic 1, roughness 0.6, base colour (0.95, 0.64, "
        "0.54): one GGX lobe, nothing to choose between; a point light of intensity 12 at (1.6, 1.4, 2.4), "
        "beside the camera, so that a broad highlight and grazing light towards the terminator are both "
        "seen; nothing else (a black background). Camera at (0, 0.4, 3.4) looking at the origin, yfov "
        "38 degrees.",
        "No closed form: the suite's reference.", {})
    copper = g.material("rough copper", (0.95, 0.64, 0.54), 1.0, 0.6)
    doc.add_mesh(g.flat_icosphere_mesh("ball", copper, 4, 0.9, g.UNSIGNED_INT))
    doc.add_point_light("point light", (1.6, 1.4, 2.4), (1.0, 1.0, 1.0), 12.0)
    eye = (0.0, 0.4, 3.4)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((0.0, 0.0, 0.0), eye)), math.radians(38.0))
    return doc


def glass_pane():
    """A smooth glass pane between the camera and a lit Lambert corner: radiance crosses the glass in
    and out again, so the eta^2 scalings of the two faces cancel, while the Fresnel choice of
    reflection or refraction (eta inverted inside) and the delta lobes act at both faces: a
    Fresnel or delta-lobe error fails it, an eta^2 error does not (camera-in-glass fails for all
    three)."""
    doc = g.PunctualDocument(
        "Conformance: smooth refraction through a pane, without the eta^2 scaling (it cancels between "
        "the two faces). A Lambert floor y = 0 (0.6) and back wall z = -2 (0.65), both ending at z = 0.3: "
        "nothing diffuse lies in front of the pane, so the light the pane transmits forward falls into the "
        "void and throws no caustic; two Lambert blocks [-1.2,-0.4]x[0,0.9]x[-1.4,-0.6] (0.75, 0.4, 0.3) "
        "and [0.2,0.9]x[0,0.6]x[-1.0,-0.3] (0.3, 0.5, 0.75); a smooth glass pane (transmission 1, ior 1.5) "
        "[-1.1,1.1]x[0.15,1.75]x[0.35,0.5]; a one-sided area light facing down at y = 2.6 (x in "
        "[-1.5,1.5], z in [-1.6,-0.2], radiance (7,6.6,6)) behind the pane. Camera at (0.9, 1.25, 3.2) "
        "looking at (-0.2, 0.6, -1.0), yfov 45 degrees: the blocks seen through the pane and beside it.",
        "No closed form: the suite's reference.", {})
    floor_mat, wall = g.lambert("floor", (0.6, 0.6, 0.6)), g.lambert("wall", (0.65, 0.65, 0.65))
    doc.add_mesh(quad("floor", floor_mat, [(-4.0, 0.0, -2.0), (4.0, 0.0, -2.0), (4.0, 0.0, 0.3), (-4.0, 0.0, 0.3)],
                      (0.0, 1.0, 0.0)))
    doc.add_mesh(quad("back wall", wall, [(-4.0, 0.0, -2.0), (4.0, 0.0, -2.0), (4.0, 6.0, -2.0), (-4.0, 6.0, -2.0)],
                      (0.0, 0.0, 1.0)))
    downward_lamp(doc, 2.6, ((-1.5, -1.6), (1.5, -0.2)), (7.0, 6.6, 6.0))
    doc.add_mesh(g.box_mesh("red block", g.lambert("red", (0.75, 0.4, 0.3)), (-1.2, 0.0, -1.4), (-0.4, 0.9, -0.6), False,
                            skip=("y-",)))
    doc.add_mesh(g.box_mesh("blue block", g.lambert("blue", (0.3, 0.5, 0.75)), (0.2, 0.0, -1.0), (0.9, 0.6, -0.3), False,
                            skip=("y-",)))
    glass = g.material("glass", (1.0, 1.0, 1.0), 0.0, 0.0,
                       {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.5}})
    doc.add_mesh(g.box_mesh("glass pane", glass, (-1.1, 0.15, 0.35), (1.1, 1.75, 0.5), False))
    eye = (0.9, 1.25, 3.2)
    doc.set_camera("camera", eye, g.rotation_to(g.sub((-0.2, 0.6, -1.0), eye)), math.radians(45.0))
    return doc


def main():
    g.write_gltf(lights_room(), "lights-room.gltf")
    g.write_gltf(glass_room(
        "Conformance: the camera inside a dielectric. A Lambert room [-2,2]x[0,2.5]x[-2,2] (white, a green "
        "wall at x = -2), a rough metal floor (metallic 1, roughness 0.3), a Lambert block, a one-sided "
        "area light (1 x 1, radiance (12,11,9)) under the ceiling; the camera at (0,1.3,1.5) sits inside a "
        "closed smooth glass box [-0.35,0.35]x[0.9,1.6]x[1.15,1.85] (IOR 1.5): every camera ray refracts "
        "out of the glass, so radiance reaching the camera is scaled by eta^2 going into the denser medium.",
        True), "camera-in-glass.gltf")
    g.write_gltf(glass_room(
        "Conformance: a light inside a dielectric. The room of camera-in-glass.gltf with a Lambert floor (0.6, "
        "0.6, 0.55) and without the area light; a "
        "point light (intensity 6) at the centre of a closed smooth glass sphere (radius 0.35, IOR 1.5, "
        "smooth normals) at (1.2,1.6,1.3), behind the camera at (0.3,1.3,1.2) (looking at (-1,0.6,-1), yfov "
        "65 degrees): all light leaves through the glass (delta refraction), so only light tracing and "
        "bidirectional estimators sample it (the camera never sees the glass); importance carries no eta^2.",
        False), "light-in-glass.gltf")
    ortho_rough_glass()
    g.write_gltf(layered_materials(), "layered-materials.gltf")
    g.write_gltf(sun_courtyard(), "sun-courtyard.gltf")
    g.write_gltf(lobe_box(), "lobe-box.gltf")
    g.write_gltf(sheen_sphere(), "sheen-sphere.gltf")
    g.write_gltf(alpha_cutouts(), "alpha-cutouts.gltf")
    ortho_camera()
    g.write_gltf(mirror_room(), "mirror-room.gltf")
    g.write_gltf(glossy_point_light(), "glossy-point-light.gltf")
    g.write_gltf(glass_pane(), "glass-pane.gltf")


if __name__ == "__main__":
    main()
