#!/usr/bin/python3
"""Writes the fuzzing seed corpus fuzz/seeds/: small glTF/GLB files, one per class of hostile
input (forged image headers, truncated images, a directory as a uri, absurd sizes, huge light
intensities, deep nesting, wrong JSON types, ...) and one per glTF feature the loader handles
(textures, samplers, both camera kinds, punctual lights, KHR_materials_*, sparse accessors,
morph targets, skins, instancing, GLB). Seeds that load are as useful as seeds that fail: the
fuzzer mutates them into the neighbouring hostile inputs. Deterministic; standard library only.

Usage: /usr/bin/python3 fuzz/make_hostile_seeds.py [out-dir]   (default: fuzz/seeds)
The fuzzer writes its input to /tmp, so relative uris resolve there ("." is /tmp itself)."""
import base64
import copy
import json
import os
import struct
import sys
import zlib

# An 8x8 grey baseline JPEG (oiiotool, quality 50, 4:4:4) with its metadata segments stripped below.
JPEG_8X8 = base64.b64decode(
    "/9j/4AAQSkZJRgABAQAAAQABAAD/4QGCRXhpZgAASUkqACYBAABvaWlvdG9vbCAtLXBhdHRlcm4gY29uc3RhbnQ6Y29sb3I9MC41IDh4OCAxIC1kIHVpbnQ4"
    "IC0tYXR0cmliIGpwZWc6c3Vic2FtcGxpbmcgNDo0OjQgLS1hdHRyaWIgQ29tcHJlc3Npb24ganBlZzo1MCAtbyAvdG1wL3RpbnkyLmpwZwBPcGVuSW1hZ2VJ"
    "TyAyLjQuNy4xIDogb2lpb3Rvb2wgLS1wYXR0ZXJuIGNvbnN0YW50OmNvbG9yPTAuNSA4eDggMSAtZCB1aW50OCAtLWF0dHJpYiBqcGVnOnN1YnNhbXBsaW5n"
    "IDQ6NDo0IC0tYXR0cmliIENvbXByZXNzaW9uIGpwZWc6NTAgLW8gL3RtcC90aW55Mi5qcGcAAgAxAQIAmgAAAIwAAABphwQAAQAAAEQBAAAAAAAABAAAkAcA"
    "BAAAADAyMzABkQcABAAAAAECAwATkgIAhAAAAAgAAAAAoAcABAAAADAxMDAAAAAA/+0AulBob3Rvc2hvcCAzLjAAOEJJTQQEAAAAAACeHAJBAJlPcGVuSW1h"
    "Z2VJTyAyLjQuNy4xIDogb2lpb3Rvb2wgLS1wYXR0ZXJuIGNvbnN0YW50OmNvbG9yPTAuNSA4eDggMSAtZCB1aW50OCAtLWF0dHJpYiBqcGVnOnN1YnNhbXBs"
    "aW5nIDQ6NDo0IC0tYXR0cmliIENvbXByZXNzaW9uIGpwZWc6NTAgLW8gL3RtcC90aW55Mi5qcGf/2wBDABALDA4MChAODQ4SERATGCgaGBYWGDEjJR0oOjM9"
    "PDkzODdASFxOQERXRTc4UG1RV19iZ2hnPk1xeXBkeFxlZ2P/wAALCAAIAAgBAREA/8QAHwAAAQUBAQEBAQEAAAAAAAAAAAECAwQFBgcICQoL/8QAtRAAAgED"
    "AwIEAwUFBAQAAAF9AQIDAAQRBRIhMUEGE1FhByJxFDKBkaEII0KxwRVS0fAkM2JyggkKFhcYGRolJicoKSo0NTY3ODk6Q0RFRkdISUpTVFVWV1hZWmNkZWZn"
    "aGlqc3R1dnd4eXqDhIWGh4iJipKTlJWWl5iZmqKjpKWmp6ipqrKztLW2t7i5usLDxMXGx8jJytLT1NXW19jZ2uHi4+Tl5ufo6erx8vP09fb3+Pn6/9oACAEB"
    "AAA/ACv/2Q==")


def png(w, h, pixels=None, channels=3):
    raw = b"".join(b"\0" + bytes(pixels[y * w * channels:(y + 1) * w * channels]) if pixels else b"\0" + bytes(w * channels)
                   for y in range(h))
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    ctype = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, ctype, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def png_claiming(w, h):
    """A well-formed PNG whose IHDR claims w x h pixels over a few bytes of pixel data."""
    p = bytearray(png(1, 1))
    p[16:24] = struct.pack(">II", w, h)
    p[29:33] = struct.pack(">I", zlib.crc32(bytes(p[12:29])) & 0xFFFFFFFF)
    return bytes(p)


def jpeg_claiming(w, h):
    """The 40-byte kind of JPEG of issue 12: SOI, a frame header claiming w x h, a scan, EOI."""
    sof = b"\xff\xc0\x00\x0b\x08" + struct.pack(">HH", h, w) + b"\x01\x01\x11\x00"
    sos = b"\xff\xda\x00\x08\x01\x01\x00\x00\x3f\x00"
    return b"\xff\xd8" + sof + sos + b"\x00\x00\x00\x00\xff\xd9"


def data_uri(data, mime="application/octet-stream"):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


class Doc:
    """A glTF document with one triangle (positions, normals, uvs, indices) in a data-URI buffer."""

    def __init__(self):
        self.bin = bytearray()
        self.j = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                  "nodes": [{"mesh": 0}], "meshes": [], "accessors": [], "bufferViews": [], "buffers": []}
        pos = self.accessor(struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0), 5126, 3, "VEC3",
                            {"min": [0, 0, 0], "max": [1, 1, 0]})
        nrm = self.accessor(struct.pack("<9f", 0, 0, 1, 0, 0, 1, 0, 0, 1), 5126, 3, "VEC3")
        uv = self.accessor(struct.pack("<6f", 0, 0, 1, 0, 0, 1), 5126, 3, "VEC2")
        idx = self.accessor(struct.pack("<3H", 0, 1, 2), 5123, 3, "SCALAR")
        self.j["meshes"].append({"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv},
                                                 "indices": idx, "material": 0}]})
        self.j["materials"] = [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1]},
                                "emissiveFactor": [1, 1, 1]}]

    def view(self, data):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.j["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        return len(self.j["bufferViews"]) - 1

    def accessor(self, data, ctype, count, typ, extra=None):
        a = {"bufferView": self.view(data), "componentType": ctype, "count": count, "type": typ}
        a.update(extra or {})
        self.j["accessors"].append(a)
        return len(self.j["accessors"]) - 1

    def texture(self, image, sampler=None):
        self.j.setdefault("images", []).append(image)
        t = {"source": len(self.j["images"]) - 1}
        if sampler is not None:
            self.j.setdefault("samplers", []).append(sampler)
            t["sampler"] = len(self.j["samplers"]) - 1
        self.j.setdefault("textures", []).append(t)
        self.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": len(self.j["textures"]) - 1}
        return self

    def light(self, light, node_extra=None):
        self.j.setdefault("extensionsUsed", []).append("KHR_lights_punctual")
        self.j.setdefault("extensions", {})["KHR_lights_punctual"] = {"lights": [light]}
        n = {"translation": [0.2, 0.2, 2], "extensions": {"KHR_lights_punctual": {"light": 0}}}
        n.update(node_extra or {})
        self.j["nodes"].append(n)
        self.j["scenes"][0]["nodes"].append(len(self.j["nodes"]) - 1)
        self.j["materials"][0].pop("emissiveFactor", None)
        return self

    def gltf(self):
        out = copy.deepcopy(self.j)
        out["buffers"] = [{"byteLength": len(self.bin), "uri": data_uri(bytes(self.bin))}]
        return json.dumps(out, separators=(",", ":")).encode()

    def glb(self):
        out = copy.deepcopy(self.j)
        out["buffers"] = [{"byteLength": len(self.bin)}]
        js = json.dumps(out, separators=(",", ":")).encode()
        js += b" " * (-len(js) % 4)
        bn = bytes(self.bin) + b"\0" * (-len(self.bin) % 4)
        body = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(bn), b"BIN\0") + bn
        return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


def strip_jpeg(j):
    """Drops APPn (except APP0) and COM segments, keeping the seed small."""
    out, pos = bytearray(j[:2]), 2
    while pos < len(j):
        m = j[pos + 1]
        if m == 0xDA:
            out += j[pos:]
            break
        n = struct.unpack(">H", j[pos + 2:pos + 4])[0]
        if not (0xE1 <= m <= 0xEF or m == 0xFE):
            out += j[pos:pos + 2 + n]
        pos += 2 + n
    return bytes(out)


def seeds():
    jpg = strip_jpeg(JPEG_8X8)
    s = {}
    # ----- hostile inputs, one per class
    s["hostile-jpeg-header-16383.gltf"] = Doc().texture({"uri": data_uri(jpeg_claiming(16383, 16383), "image/jpeg")}).gltf()
    s["hostile-png-header-16383.gltf"] = Doc().texture({"uri": data_uri(png_claiming(16383, 16383), "image/png")}).gltf()
    s["hostile-png-header-100000.gltf"] = Doc().texture({"uri": data_uri(png_claiming(100000, 3), "image/png")}).gltf()
    good = png(4, 4, list(range(48)))
    s["hostile-png-truncated.gltf"] = Doc().texture({"uri": data_uri(good[:len(good) // 2], "image/png")}).gltf()
    s["hostile-jpeg-truncated.gltf"] = Doc().texture({"uri": data_uri(jpg[:len(jpg) - 6], "image/jpeg")}).gltf()
    s["hostile-image-not-png-or-jpeg.gltf"] = Doc().texture({"uri": data_uri(b"BM" + bytes(60), "image/bmp")}).gltf()
    d = Doc()
    d.j["images"] = [{"bufferView": d.view(good), "mimeType": "image/png"}]
    d.j["bufferViews"][-1]["byteLength"] = 1 << 30
    d.j["textures"] = [{"source": 0}]
    d.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    s["hostile-image-bufferview-past-end.glb"] = d.glb()
    s["hostile-image-uri-directory.gltf"] = Doc().texture({"uri": "."}).gltf()
    s["hostile-image-uri-missing.gltf"] = Doc().texture({"uri": "no-such-image.png"}).gltf()
    d = json.loads(Doc().gltf())
    d["buffers"][0] = {"byteLength": d["buffers"][0]["byteLength"], "uri": "."}
    s["hostile-buffer-uri-directory.gltf"] = json.dumps(d).encode()
    d["buffers"][0]["uri"] = "/dev/zero"
    s["hostile-buffer-uri-device.gltf"] = json.dumps(d).encode()
    d["buffers"][0]["uri"] = "no-such-buffer.bin"
    s["hostile-buffer-uri-missing.gltf"] = json.dumps(d).encode()
    d = json.loads(Doc().gltf())
    d["buffers"][0]["byteLength"] = 10 ** 15
    s["hostile-buffer-bytelength-absurd.gltf"] = json.dumps(d).encode()
    d = json.loads(Doc().gltf())
    d["accessors"][0]["count"] = 2 ** 31 - 1
    s["hostile-accessor-count-absurd.gltf"] = json.dumps(d).encode()
    d["accessors"][0]["count"] = 3
    d["bufferViews"][0]["byteStride"] = 252
    s["hostile-bufferview-stride.gltf"] = json.dumps(d).encode()
    for kind in ("point", "directional", "spot"):
        light = {"type": kind, "intensity": 3e37}
        if kind == "spot":
            light["spot"] = {"innerConeAngle": 0.1, "outerConeAngle": 0.5}
        s["hostile-light-%s-3e37.gltf" % kind] = Doc().light(light).gltf()
    s["hostile-light-intensity-1e39.gltf"] = Doc().light({"type": "point", "intensity": 1e39}).gltf()
    s["hostile-light-intensity-0.gltf"] = Doc().light({"type": "point", "intensity": 0}).gltf()
    s["hostile-light-intensity-1e-40.gltf"] = Doc().light({"type": "point", "intensity": 1e-40}).gltf()
    s["hostile-light-spot-cone-1e-9.gltf"] = Doc().light(
        {"type": "spot", "intensity": 1, "spot": {"innerConeAngle": 0, "outerConeAngle": 1e-9}}).gltf()
    d = json.loads(Doc().gltf())
    d["materials"][0]["emissiveFactor"] = [1, 1, 1]
    d["materials"][0]["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": 3e38}}
    s["hostile-emissive-strength-3e38.gltf"] = json.dumps(d).encode()
    d = json.loads(Doc().gltf())
    nested = {}
    for _ in range(300):
        nested = {"a": [nested]}
    d["extras"] = nested
    s["hostile-deep-nesting.gltf"] = json.dumps(d).encode()
    d = json.loads(Doc().gltf())
    d["materials"][0]["doubleSided"] = 1
    d["meshes"][0]["primitives"][0]["material"] = "0"
    d["nodes"][0]["matrix"] = [1, 0, 0]
    s["hostile-wrong-types.gltf"] = json.dumps(d).encode()
    d = json.loads(Doc().gltf())
    d["nodes"][0]["children"] = [0]
    s["hostile-node-cycle.gltf"] = json.dumps(d).encode()
    d = json.loads(Doc().gltf())
    d["materials"] = [copy.deepcopy(d["materials"][0]) for _ in range(40)]
    for m in d["materials"]:
        m["occlusionTexture"] = {"index": 0}
    d["images"] = [{"uri": data_uri(png(1, 1), "image/png")}]
    d["textures"] = [{"source": 0}]
    d["meshes"] = [{"primitives": [dict(d["meshes"][0]["primitives"][0], material=i)]} for i in range(40)]
    d["nodes"] = [{"mesh": i} for i in range(40)]
    d["scenes"][0]["nodes"] = list(range(40))
    s["hostile-repeated-warnings.gltf"] = json.dumps(d).encode()
    glb = Doc().glb()
    s["hostile-glb-chunk-length.glb"] = glb[:12] + struct.pack("<I", 0x7FFFFFF0) + glb[16:]
    s["hostile-glb-truncated.glb"] = glb[:len(glb) // 2]

    # ----- features, one per kind
    s["feature-texture-png-sampler.gltf"] = Doc().texture(
        {"uri": data_uri(png(2, 2, [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]), "image/png")},
        {"magFilter": 9728, "minFilter": 9986, "wrapS": 33648, "wrapT": 33071}).gltf()
    s["feature-texture-jpeg.gltf"] = Doc().texture({"uri": data_uri(jpg, "image/jpeg")}).gltf()
    d = Doc()
    d.j["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "aspectRatio": 1.0}}]
    d.j["nodes"].append({"camera": 0, "translation": [0.3, 0.3, 3]})
    d.j["scenes"][0]["nodes"].append(1)
    s["feature-camera-perspective.gltf"] = d.gltf()
    d.j["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.01, "zfar": 10}}]
    s["feature-camera-orthographic.gltf"] = d.gltf()
    s["feature-light-point.gltf"] = Doc().light({"type": "point", "color": [1, 0.9, 0.8], "intensity": 10, "range": 5}).gltf()
    s["feature-light-spot.gltf"] = Doc().light(
        {"type": "spot", "intensity": 10, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
        {"rotation": [0, 0, 0, 1]}).gltf()
    s["feature-light-directional.gltf"] = Doc().light({"type": "directional", "intensity": 2}).gltf()
    d = Doc()
    d.j["extensionsUsed"] = ["KHR_materials_emissive_strength", "KHR_materials_ior", "KHR_materials_transmission",
                             "KHR_materials_specular"]
    d.j["materials"] = [
        {"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}},
        {"pbrMetallicRoughness": {"roughnessFactor": 0}, "extensions": {
            "KHR_materials_ior": {"ior": 1.5}, "KHR_materials_transmission": {"transmissionFactor": 1},
            "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 1, 1]}}}]
    d.j["nodes"].append({"mesh": 0, "translation": [0, 0, -1]})
    d.j["scenes"][0]["nodes"].append(1)
    s["feature-khr-materials.gltf"] = d.gltf()
    d = Doc()
    d.j["extensionsUsed"] = ["KHR_materials_clearcoat", "KHR_materials_sheen"]
    d.j["materials"] = [{"extensions": {
        "KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatRoughnessFactor": 0.2},
        "KHR_materials_sheen": {"sheenColorFactor": [1, 0.5, 0.2], "sheenRoughnessFactor": 0.5}}}]
    s["feature-khr-layers.gltf"] = d.gltf()
    d = Doc()
    si = d.view(struct.pack("<H", 1) + b"\0\0")
    sv = d.view(struct.pack("<3f", 0.5, 0.5, 0))
    d.j["accessors"][0]["sparse"] = {"count": 1, "indices": {"bufferView": si, "componentType": 5123},
                                     "values": {"bufferView": sv}}
    s["feature-sparse-accessor.gltf"] = d.gltf()
    d = Doc()
    t = d.accessor(struct.pack("<9f", 0, 0, 0.5, 0, 0, 0.5, 0, 0, 0.5), 5126, 3, "VEC3")
    d.j["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": t}]
    d.j["meshes"][0]["weights"] = [0.5]
    s["feature-morph-targets.gltf"] = d.gltf()
    d = Doc()
    j = d.accessor(struct.pack("<12H", *([0] * 12)), 5121, 3, "VEC4")
    w = d.accessor(struct.pack("<12f", *([1, 0, 0, 0] * 3)), 5126, 3, "VEC4")
    ib = d.accessor(struct.pack("<16f", 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1), 5126, 1, "MAT4")
    d.j["meshes"][0]["primitives"][0]["attributes"].update({"JOINTS_0": j, "WEIGHTS_0": w})
    d.j["nodes"][0]["skin"] = 0
    d.j["nodes"].append({"translation": [0, 0, 0]})
    d.j["skins"] = [{"joints": [1], "inverseBindMatrices": ib}]
    s["feature-skin.gltf"] = d.gltf()
    d = Doc()
    d.j["nodes"] = [{"mesh": 0, "translation": [x, 0, 0], "scale": [1, 1 + x, 1]} for x in range(4)]
    d.j["nodes"].append({"children": [0, 1, 2, 3], "rotation": [0, 0.3826834, 0, 0.9238795]})
    d.j["scenes"][0]["nodes"] = [4]
    tr = d.accessor(struct.pack("<6f", 0, 0, 0, 0, 2, 0), 5126, 2, "VEC3")
    d.j["nodes"][0]["extensions"] = {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": tr}}}
    d.j["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
    s["feature-instancing.gltf"] = d.gltf()
    s["feature-glb.glb"] = Doc().glb()
    d = Doc()
    d.j["images"] = [{"bufferView": d.view(png(2, 2)), "mimeType": "image/png"}]
    d.j["textures"] = [{"source": 0}]
    d.j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    s["feature-glb-embedded-image.glb"] = d.glb()
    d = Doc()
    d.j["meshes"][0]["primitives"][0]["mode"] = 5
    d.j["animations"] = [{"channels": [], "samplers": []}]
    s["feature-strip-animation.gltf"] = d.gltf()
    return s


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "seeds")
    os.makedirs(out, exist_ok=True)
    for name, data in sorted(seeds().items()):
        assert len(data) <= 65536, name  # fuzz/run.sh runs with -max_len=65536
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)
    print("%d seeds in %s" % (len(seeds()), out))


if __name__ == "__main__":
    main()
