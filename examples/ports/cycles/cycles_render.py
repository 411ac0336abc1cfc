# Render a bdptref glTF scene with Blender Cycles under bdptref's model (examples/ports/cycles/README.md).
#
#   blender -b --factory-startup --python-exit-code 1 -P cycles_render.py -- \
#       --scene S.gltf --out r.exr --spp 64 --seed 1 --width 64 --height 64 --max-depth 8
#   ... --seeds 1,2,3 --out 'dir/r{seed}.exr'      # several renders, one Blender start-up
#
# Every setting and why: README.md next to this file. The conventions it implements are
# docs/port-contract.md's.
import argparse
import base64
import json
import math
import os
import struct
import sys
import tempfile
import time

import numpy

import warnings

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    if not hasattr(numpy, "bool"):
        numpy.bool = bool  # Blender 3.4's glTF importer uses np.bool, removed from Debian 12's numpy

import bpy  # noqa: E402
from mathutils import Matrix  # noqa: E402

# glTF is Y-up, Blender Z-up: the importer maps a glTF point (x, y, z) to Blender (x, -z, y).
YUP_TO_ZUP = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))


def fail(msg):
    print("cycles_render.py: error: " + msg, file=sys.stderr)
    sys.exit(2)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="cycles_render.py", description=__doc__)
    p.add_argument("--scene", required=True, help="glTF 2.0 scene (.gltf or .glb)")
    p.add_argument("--out", required=True,
                   help="output EXR; with --seeds it must contain {seed}")
    p.add_argument("--spp", type=int, required=True)
    p.add_argument("--seed", type=int, help="one render with this seed")
    p.add_argument("--seeds", help="several renders in one process: a list separated by commas or spaces")
    p.add_argument("--width", type=int, default=64)
    p.add_argument("--height", type=int, default=64)
    p.add_argument("--size", help="WxH (overrides --width/--height)")
    p.add_argument("--max-depth", type=int, required=True,
                   help="bdptref's --max-depth D (scattering events); Cycles max_bounces = D - 1")
    p.add_argument("--materials", choices=["same-model", "stock"], default="same-model")
    p.add_argument("--env", default="", help="constant environment r,g,b (bdptref --env)")
    p.add_argument("--env-map", default="", help="equirectangular .hdr (bdptref --env-map)")
    p.add_argument("--env-scale", default="", help="its scale (bdptref --env-scale)")
    p.add_argument("--threads", type=int, default=0, help="0: all cores")
    p.add_argument("--cycles-workarounds", action="store_true",
                   help="avoid the two Cycles 3.x biases the witnesses show (README.md, 'Known Cycles "
                        "biases'): --unit-scale auto and no Russian roulette (min_light_bounces = "
                        "max_bounces); the image's expected value is unchanged, only Cycles' errors go")
    p.add_argument("--unit-scale", default="1",
                   help="scale the whole scene by this factor about the origin (point and spot light "
                        "power by its square, so that the image does not change): Cycles 3.x chooses "
                        "its triangle-light sampling by a unit-dependent test (README.md, 'Known Cycles "
                        "biases'); 0.001 renders a millimetre scene such as the Cornell box in metres")
    p.add_argument("--cycles-set", action="append", default=[], metavar="NAME=VALUE",
                   help="set scene.cycles.NAME (an experiment: e.g. direct_light_sampling_type="
                        "FORWARD_PATH_TRACING); repeatable")
    p.add_argument("--no-light-sampling", action="store_true",
                   help="an experiment: no next-event estimation of emissive materials (their "
                        "'Multiple Importance' off), emission found by BSDF sampling only")
    p.add_argument("--scale", type=float, default=1.0,
                   help="multiply the output (Cycles' film exposure): a deliberately wrong port for "
                        "tests (default 1)")
    a = p.parse_args(argv)
    if a.size:
        w, h = a.size.lower().split("x")
        a.width, a.height = int(w), int(h)
    if (a.seed is None) == (a.seeds is None):
        fail("give exactly one of --seed S and --seeds S1,S2,...")
    a.seed_list = [a.seed] if a.seed is not None else [int(s) for s in a.seeds.replace(",", " ").split()]
    if len(a.seed_list) > 1 and "{seed}" not in a.out:
        fail("--seeds with several seeds needs {seed} in --out (got %r)" % a.out)
    if a.max_depth < 1:
        # bdptref depth 0 = emitters seen directly; Cycles' max_bounces 0 still adds direct light.
        fail("--max-depth %d cannot be expressed in Cycles (max_bounces = depth - 1 >= 0)" % a.max_depth)
    if a.spp < 1:
        fail("--spp must be >= 1")
    if a.cycles_workarounds and a.unit_scale == "1":
        a.unit_scale = "auto"
    if a.unit_scale != "auto":
        a.unit_scale = float(a.unit_scale)
    return a


# ---------------------------------------------------------------- glTF JSON (read ourselves)

def read_gltf(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":
        length = struct.unpack_from("<I", data, 12)[0]
        js = json.loads(data[20:20 + length].decode("utf-8"))
        return js, data, True
    return json.loads(data.decode("utf-8")), data, False


def write_tagged_copy(path, js, raw, is_glb, tmpdir):
    """A copy of the file whose materials, nodes and lights carry unique names, so that the
    importer's Blender objects can be matched to the glTF's indices (names may repeat in a file).
    Relative URIs are made absolute (the copy lives elsewhere)."""
    js = json.loads(json.dumps(js))
    base = os.path.dirname(os.path.abspath(path))
    for i, m in enumerate(js.get("materials", [])):
        m["name"] = "bdptref_mat_%d" % i
    for i, n in enumerate(js.get("nodes", [])):
        n["name"] = "bdptref_node_%d" % i
    for i, l in enumerate(js.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])):
        l["name"] = "bdptref_light_%d" % i
    for key in ("buffers", "images"):
        for b in js.get(key, []):
            uri = b.get("uri")
            if uri and not uri.startswith("data:") and not os.path.isabs(uri):
                b["uri"] = os.path.join(base, uri)
    out = os.path.join(tmpdir, "scene" + (".glb" if is_glb else ".gltf"))
    text = json.dumps(js).encode("utf-8")
    if is_glb:
        text += b" " * ((4 - len(text) % 4) % 4)
        length = struct.unpack_from("<I", raw, 12)[0]
        rest = raw[20 + length:]  # the BIN chunk, unchanged
        body = struct.pack("<II", len(text), 0x4E4F534A) + text + rest
        blob = struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body
    else:
        blob = text
    with open(out, "wb") as f:
        f.write(blob)
    return out


def node_local(n):
    if "matrix" in n:
        m = n["matrix"]
        return Matrix([[m[c * 4 + r] for c in range(4)] for r in range(4)])
    t = n.get("translation", [0, 0, 0])
    q = n.get("rotation", [0, 0, 0, 1])  # x, y, z, w
    s = n.get("scale", [1, 1, 1])
    from mathutils import Quaternion
    R = Quaternion((q[3], q[0], q[1], q[2])).to_matrix().to_4x4()
    S = Matrix.Diagonal((s[0], s[1], s[2], 1.0))
    return Matrix.Translation(t) @ R @ S


def walk_nodes(js):
    """(node index, world matrix in glTF space) in pre-order, children in file order."""
    scenes = js.get("scenes", [])
    roots = scenes[js.get("scene", 0)]["nodes"] if scenes else []
    out = []

    def rec(i, parent):
        n = js["nodes"][i]
        w = parent @ node_local(n)
        out.append((i, w))
        for c in n.get("children", []):
            rec(c, w)
    for r in roots:
        rec(r, Matrix.Identity(4))
    return out


# ---------------------------------------------------------------- scene set-up

def setup_camera(js, nodes, a):
    cams = [(i, w) for i, w in nodes if "camera" in js["nodes"][i]]
    if not cams:
        fail("the scene has no camera (bdptref's default camera is not reproduced here)")
    i, w = cams[0]  # bdptref: the first camera node instance in pre-order
    gcam = js["cameras"][js["nodes"][i]["camera"]]
    data = bpy.data.cameras.new("bdptref_camera")
    data.sensor_fit = "VERTICAL"  # bdptref keeps the vertical extent (yfov / ymag)
    if gcam["type"] == "perspective":
        data.type = "PERSP"
        data.angle_y = gcam["perspective"]["yfov"]
    else:
        data.type = "ORTHO"
        data.ortho_scale = 2.0 * gcam["orthographic"]["ymag"]
    data.clip_start = 1e-6  # bdptref ignores znear/zfar
    data.clip_end = 1e9
    data.shift_x = data.shift_y = 0.0
    obj = bpy.data.objects.new("bdptref_camera", data)
    bpy.context.scene.collection.objects.link(obj)
    # Both conventions look down local -Z with +Y up: only the world axes change.
    obj.matrix_world = YUP_TO_ZUP @ w
    bpy.context.scene.camera = obj


def lambert_material(name, gm):
    """bdptref's model for a Lambert material (metallic 0, specularFactor 0): Diffuse BSDF of the
    base colour plus one-sided emission of radiance emissiveFactor x emissive_strength."""
    pbr = gm.get("pbrMetallicRoughness", {})
    base = pbr.get("baseColorFactor", [1, 1, 1, 1])
    ext = gm.get("extensions", {})
    strength = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
    le = [c * strength for c in gm.get("emissiveFactor", [0, 0, 0])]
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    diff = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diff.inputs["Color"].default_value = (base[0], base[1], base[2], 1.0)
    diff.inputs["Roughness"].default_value = 0.0  # Lambert (Oren-Nayar above 0)
    shader = diff.outputs["BSDF"]
    if max(le) > 0:
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (le[0], le[1], le[2], 1.0)
        em.inputs["Strength"].default_value = 1.0  # Cycles' emission strength 1 = radiance
        emit = em.outputs["Emission"]
        if not gm.get("doubleSided", False):
            # one-sided: emission only on the front face (bdptref: counter-clockwise side)
            geo = nt.nodes.new("ShaderNodeNewGeometry")
            mix = nt.nodes.new("ShaderNodeMixShader")
            black = nt.nodes.new("ShaderNodeEmission")
            black.inputs["Strength"].default_value = 0.0
            nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
            nt.links.new(emit, mix.inputs[1])
            nt.links.new(black.outputs["Emission"], mix.inputs[2])
            emit = mix.outputs["Shader"]
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(shader, add.inputs[0])
        nt.links.new(emit, add.inputs[1])
        shader = add.outputs["Shader"]
    nt.links.new(shader, out.inputs["Surface"])
    return mat


def not_lambert(gm):
    """Why a glTF material is outside the same-model driver's model, or None."""
    pbr = gm.get("pbrMetallicRoughness", {})
    ext = gm.get("extensions", {})
    if pbr.get("metallicFactor", 1.0) != 0:
        return "metallicFactor %g" % pbr.get("metallicFactor", 1.0)
    if ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0) != 0:
        return "specular (KHR_materials_specular.specularFactor is not 0)"
    for k in ("KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_clearcoat",
              "KHR_materials_sheen"):
        if k in ext:
            return k
    for k in ("baseColorTexture", "metallicRoughnessTexture"):
        if k in pbr:
            return k
    for k in ("emissiveTexture", "normalTexture"):
        if k in gm:
            return k
    if gm.get("alphaMode", "OPAQUE") != "OPAQUE":
        return "alphaMode " + gm["alphaMode"]
    return None


EMISSIVE = set()


def setup_materials(js):
    gmats = js.get("materials", [])
    made = {}
    for mat in list(bpy.data.materials):
        if not mat.name.startswith("bdptref_mat_"):
            continue
        idx = int(mat.name[len("bdptref_mat_"):].split(".")[0])
        gm = gmats[idx]
        why = not_lambert(gm)
        if why:
            print("cycles_render.py: warning: material %d (%s) is not Lambert (%s): "
                  "rendered with the importer's Principled material, not bdptref's model"
                  % (idx, gm.get("name", "?"), why), file=sys.stderr)
            continue
        if idx not in made:
            made[idx] = lambert_material("bdptref_lambert_%d" % idx, gm)
            if max(gm.get("emissiveFactor", [0, 0, 0])) > 0:
                EMISSIVE.add(made[idx])
        for obj in bpy.data.objects:
            for slot in obj.material_slots:
                if slot.material == mat:
                    slot.material = made[idx]
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        if len(obj.material_slots) == 0 or any(s.material is None for s in obj.material_slots):
            # bdptref: glTF's default material (base colour 1, metallic 1, roughness 1)
            print("cycles_render.py: warning: %s has primitives without a material (not bdptref's "
                  "default material)" % obj.name, file=sys.stderr)
        if len(obj.data.color_attributes) > 0:
            print("cycles_render.py: warning: %s has vertex colours (COLOR_0): bdptref multiplies "
                  "the base colour by them, this driver does not" % obj.name, file=sys.stderr)


def setup_lights(js, nodes):
    glights = js.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    by_node = {}
    for obj in bpy.data.objects:
        if obj.type == "LIGHT" and obj.name.startswith("bdptref_node_"):
            by_node[int(obj.name[len("bdptref_node_"):].split(".")[0])] = obj
    for i, w in nodes:
        ext = js["nodes"][i].get("extensions", {}).get("KHR_lights_punctual")
        if ext is None:
            continue
        gl = glights[ext["light"]]
        obj = by_node.get(i)
        if obj is None:
            fail("node %d's light was not imported" % i)
        L = obj.data
        col = gl.get("color", [1, 1, 1])
        I = gl.get("intensity", 1.0)
        L.color = col
        L.use_shadow = True
        L.cycles.use_multiple_importance_sampling = True
        L.cycles.max_bounces = 1024
        if gl["type"] in ("point", "spot"):
            # bdptref: radiant intensity I = color x intensity (candela read as W/sr, no 683).
            # A Cycles point/spot light of power P watts has intensity P / (4 pi) W/sr.
            L.energy = 4.0 * math.pi * I
            L.shadow_soft_size = 0.0  # a true point (the importer leaves Blender's 0.25 m)
            if gl["type"] == "spot":
                sp = gl.get("spot", {})
                inner, outer = sp.get("innerConeAngle", 0.0), sp.get("outerConeAngle", math.pi / 4)
                # Cycles: smoothstep over cos from cos(outer) to cos(outer) + (1 - cos outer) blend;
                # glTF/bdptref: the square of a linear ramp in cos from cos outer to cos inner.
                # The blend below makes the ramps span the same cosines; the shapes still differ
                # (README.md: spot lights).
                L.spot_size = 2.0 * outer
                co, ci = math.cos(outer), math.cos(inner)
                L.spot_blend = min(1.0, max(0.0, (ci - co) / (1.0 - co)))
        elif gl["type"] == "directional":
            L.energy = I  # Cycles sun strength: irradiance W/m^2 (bdptref: lux read as W/m^2)
            L.angle = 0.0
        # position and direction: both look down local -Z
        obj.matrix_world = YUP_TO_ZUP @ w


def setup_world(a):
    scene = bpy.context.scene
    world = bpy.data.worlds.new("bdptref_world")
    scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputWorld")
    bg = nt.nodes.new("ShaderNodeBackground")
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    if a.env_map:
        # bdptref: u = 0.5 + atan2(z, x)/2pi, v = acos(y)/pi (top row +Y) in glTF axes. Blender's
        # equirectangular lookup of the Z-up direction d = (x, -z, y) is u = 0.5 - atan2(d.y, d.x)/2pi
        # = 0.5 + atan2(z, x)/2pi and the same elevation: the same map, no rotation needed.
        tex = nt.nodes.new("ShaderNodeTexEnvironment")
        tex.image = bpy.data.images.load(os.path.abspath(a.env_map))
        tex.image.colorspace_settings.name = "Linear"
        tex.interpolation = "Closest"  # bdptref: piecewise constant texels
        nt.links.new(tex.outputs["Color"], bg.inputs["Color"])
        bg.inputs["Strength"].default_value = float(a.env_scale) if a.env_scale else 1.0
        world.cycles.sample_as_light = True
        world.cycles.sampling_method = "MANUAL"
        world.cycles.sample_map_resolution = max(tex.image.size[0], 16)
    elif a.env:
        r, g, b = [float(x) for x in a.env.split(",")]
        bg.inputs["Color"].default_value = (r, g, b, 1.0)
        bg.inputs["Strength"].default_value = 1.0
    else:
        bg.inputs["Color"].default_value = (0, 0, 0, 1)
        bg.inputs["Strength"].default_value = 0.0


def setup_render(a):
    scene = bpy.context.scene
    r = scene.render
    c = scene.cycles
    r.engine = "CYCLES"
    c.device = "CPU"
    r.resolution_x, r.resolution_y, r.resolution_percentage = a.width, a.height, 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.film_transparent = False
    r.use_persistent_data = True  # keep the BVH between the renders of --seeds
    if a.threads > 0:
        r.threads_mode, r.threads = "FIXED", a.threads
    c.samples = a.spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.use_preview_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.light_sampling_threshold = 0.0
    c.use_animated_seed = False
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0
    c.use_fast_gi = False
    c.use_guiding = False  # path guiding (CPU) learns from samples: off
    c.direct_light_sampling_type = "MULTIPLE_IMPORTANCE_SAMPLING"
    bounces = a.max_depth - 1  # bdptref depth D = D scattering events; Cycles counts bounces after the first hit
    c.max_bounces = bounces
    c.diffuse_bounces = bounces
    c.glossy_bounces = bounces
    c.transmission_bounces = bounces
    c.volume_bounces = bounces
    c.transparent_max_bounces = 1024  # alpha pass-through is not a scattering event
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0  # box of one pixel: samples uniform in their own pixel
    c.film_exposure = a.scale  # a multiplier in Cycles (1 = none; --scale makes a wrong port on purpose)
    c.use_auto_tile = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.sequencer_colorspace_settings.name = "Linear"
    s = r.image_settings
    s.file_format = "OPEN_EXR"
    s.color_depth = "32"
    s.color_mode = "RGB"
    s.exr_codec = "ZIP"
    for obj in bpy.data.objects:
        if obj.type == "MESH":
            # Cycles' shadow-terminator offsets move shadow-ray origins off smooth-shaded
            # triangles (geometry offset default 0.1): bdptref has none.
            obj.cycles.shadow_terminator_offset = 0.0
            obj.cycles.shadow_terminator_geometry_offset = 0.0


def auto_unit_scale(emissive_materials):
    """The largest factor <= 1 that puts every emissive triangle's Cycles 3.x spherical-sampling
    region (receivers closer to its plane than 2 A e, A its area, e its longest edge: the test
    compares a length with |N|^2-normalised distance, README.md) within 1e-4 units of its plane.
    2 A e scales as s^3, distances as s."""
    worst = 0.0
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        M = obj.matrix_world
        me = obj.data
        verts = [M @ v.co for v in me.vertices]
        for poly in me.polygons:
            mat = obj.material_slots[poly.material_index].material if obj.material_slots else None
            if emissive_materials is not None and mat not in emissive_materials:
                continue
            ids = list(poly.vertices)
            for k in range(1, len(ids) - 1):
                p0, p1, p2 = verts[ids[0]], verts[ids[k]], verts[ids[k + 1]]
                area = 0.5 * (p1 - p0).cross(p2 - p0).length
                edge = max((p1 - p0).length, (p2 - p0).length, (p2 - p1).length)
                worst = max(worst, 2.0 * area * edge)
    if worst <= 1e-4:
        return 1.0
    return (1e-4 / worst) ** (1.0 / 3.0)


def apply_unit_scale(s):
    """Every length times s; the radiance image unchanged (area emission is radiance; point and
    spot intensities times s^2 keep I / d^2; directional irradiance and the camera's angles are
    scale-free; an orthographic camera's extent is scaled with the scene)."""
    if s == 1.0:
        return
    S = Matrix.Scale(s, 4)
    cam = bpy.context.scene.camera
    for obj in bpy.data.objects:
        if obj.parent is None and obj != cam:
            obj.matrix_world = S @ obj.matrix_world
        if obj.type == "LIGHT" and obj.data.type in ("POINT", "SPOT"):
            obj.data.energy *= s * s
    loc, rot, _ = cam.matrix_world.decompose()
    cam.matrix_world = Matrix.Translation(loc * s) @ rot.to_matrix().to_4x4()
    if cam.data.type == "ORTHO":
        cam.data.ortho_scale *= s


def scene_cycles():
    return bpy.context.scene.cycles


def main():
    a = parse_args()
    t0 = time.time()
    scene_path = os.path.abspath(a.scene)
    js, raw, is_glb = read_gltf(scene_path)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    with tempfile.TemporaryDirectory(prefix="cycles_render_") as tmp:
        tagged = write_tagged_copy(scene_path, js, raw, is_glb, tmp)
        res = bpy.ops.import_scene.gltf(filepath=tagged, import_shading="NORMALS",
                                        merge_vertices=False)
        if "FINISHED" not in res:
            fail("the glTF importer failed on " + a.scene)
    for obj in list(bpy.data.objects):
        if obj.type == "CAMERA":
            bpy.data.objects.remove(obj)
    nodes = walk_nodes(js)
    setup_camera(js, nodes, a)
    if a.materials == "same-model":
        setup_materials(js)
        setup_lights(js, nodes)
    setup_world(a)
    setup_render(a)
    if a.unit_scale == "auto":
        a.unit_scale = auto_unit_scale(EMISSIVE if a.materials == "same-model" else None)
    apply_unit_scale(a.unit_scale)
    if a.cycles_workarounds:
        scene_cycles().min_light_bounces = a.max_depth - 1  # no Russian roulette (README.md)
    if a.no_light_sampling:
        for mat in bpy.data.materials:
            mat.cycles.sample_as_light = False
    for kv in a.cycles_set:
        k, v = kv.split("=", 1)
        old = getattr(scene_cycles(), k)
        setattr(scene_cycles(), k, type(old)(v) if not isinstance(old, bool) else v.lower() in ("1", "true", "on"))
        print("cycles_render.py: scene.cycles.%s = %r (was %r)" % (k, getattr(scene_cycles(), k), old))
    print("cycles_render.py: set up in %.2f s (materials %s, max_bounces %d, unit scale %g)"
          % (time.time() - t0, a.materials, a.max_depth - 1, a.unit_scale))
    scene = bpy.context.scene
    for seed in a.seed_list:
        t1 = time.time()
        scene.cycles.seed = seed
        out = os.path.abspath(a.out.replace("{seed}", str(seed)))
        os.makedirs(os.path.dirname(out), exist_ok=True)
        tmp_out = out + ".tmp.exr"
        scene.render.filepath = tmp_out
        bpy.ops.render.render(write_still=True)
        os.replace(tmp_out, out)
        print("cycles_render.py: seed %d: %s (%.2f s)" % (seed, out, time.time() - t1))


if __name__ == "__main__":
    main()
