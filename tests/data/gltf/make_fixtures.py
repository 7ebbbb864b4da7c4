#!/usr/bin/env python3
"""Writes the glTF fixtures for tests/unit/gltf_import_test.cpp (python3 standard library only).

Run from anywhere: python3 tests/data/gltf/make_fixtures.py
valid/   files that must import, with the values the tests check;
bad/     one malformed file per error case (the expected message is in the test's table);
../../fuzz/corpus/gltf_import/   seeds for the importer's fuzzer that reach KHR_mesh_quantization,
         matrix accessors and the non-finite checks (tests/fuzz, docs/testing.md).
"""
import base64
import copy
import json
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
VALID = os.path.join(HERE, "valid")
BAD = os.path.join(HERE, "bad")

FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125
BYTE, SHORT = 5120, 5122
FUZZ_SEEDS = os.path.join(HERE, "..", "..", "fuzz", "corpus", "gltf_import")


# --- tiny PNG writer -------------------------------------------------------------------------

def png(width, height, channels, pixels, bit_depth=8):
    """pixels: flat list of channel values, row 0 first. channels 1 grey, 2 grey-alpha, 3, 4."""
    color_type = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    fmt = ">%dH" if bit_depth == 16 else "%dB"
    raw = b""
    row_len = width * channels
    for y in range(height):
        row = pixels[y * row_len:(y + 1) * row_len]
        raw += b"\x00" + struct.pack(fmt % row_len, *row)

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) +
            chunk(b"IEND", b""))


def data_uri(data, mime="application/octet-stream"):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode("ascii"))


# 2x2 RGB: red, green / blue, white.
PNG_RGB = png(2, 2, 3, [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])
# 2x1 16-bit grey: 0 and 65535 (must come out as 0 and 255, grey expanded to RGBA).
PNG_GREY16 = png(2, 1, 1, [0, 65535], bit_depth=16)
# 1x1 grey-alpha (128, 64).
PNG_GREY_ALPHA = png(1, 1, 2, [128, 64])


# --- glTF builder ----------------------------------------------------------------------------

class Gltf:
    """Accumulates one binary buffer and the accessors that view it."""

    def __init__(self):
        self.bin = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "focal make_fixtures.py"},
                    "buffers": [], "bufferViews": [], "accessors": []}

    def view(self, data, stride=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if stride:
            v["byteStride"] = stride
        self.bin += data
        self.doc["bufferViews"].append(v)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values, ctype, atype, normalized=False, minmax=False):
        ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9,
                 "MAT4": 16}[atype]
        flat = [c for v in values for c in (v if isinstance(v, (list, tuple)) else [v])]
        code = {FLOAT: "f", UBYTE: "B", USHORT: "H", UINT: "I", BYTE: "b", SHORT: "h"}[ctype]
        data = struct.pack("<%d%s" % (len(flat), code), *flat)
        a = {"bufferView": self.view(data), "componentType": ctype,
             "count": len(flat) // ncomp, "type": atype}
        if normalized:
            a["normalized"] = True
        if minmax:
            a["min"] = [min(flat[i::ncomp]) for i in range(ncomp)]
            a["max"] = [max(flat[i::ncomp]) for i in range(ncomp)]
        self.doc["accessors"].append(a)
        return len(self.doc["accessors"]) - 1

    def image_view(self, data, mime):
        return {"bufferView": self.view(data), "mimeType": mime}

    def finish(self, uri=None):
        doc = copy.deepcopy(self.doc)
        buf = {"byteLength": len(self.bin)}
        if uri is None:
            buf["uri"] = data_uri(bytes(self.bin))
        elif uri != "":
            buf["uri"] = uri
        doc["buffers"] = [buf]
        return doc


def write_json(folder, name, doc):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def write_glb(folder, name, doc, bin_data):
    js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    js += b" " * ((4 - len(js) % 4) % 4)
    bin_data = bytes(bin_data) + b"\x00" * ((4 - len(bin_data) % 4) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(bin_data),
                                                                       0x004E4942) + bin_data
    with open(os.path.join(folder, name), "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)


TRI = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]


def triangle_doc(extra_nodes=None):
    g = Gltf()
    pos = g.accessor(TRI, FLOAT, "VEC3", minmax=True)
    idx = g.accessor([0, 1, 2], USHORT, "SCALAR")
    g.doc["meshes"] = [{"name": "tri", "primitives": [{"attributes": {"POSITION": pos},
                                                       "indices": idx}]}]
    g.doc["nodes"] = [{"name": "tri_node", "mesh": 0}] + (extra_nodes or [])
    g.doc["scenes"] = [{"nodes": [0]}]
    g.doc["scene"] = 0
    return g


# --- valid fixtures --------------------------------------------------------------------------

def make_valid():
    # triangle.gltf + triangle.bin: external buffer.
    g = triangle_doc()
    write_json(VALID, "triangle.gltf", g.finish(uri="triangle.bin"))
    with open(os.path.join(VALID, "triangle.bin"), "wb") as f:
        f.write(bytes(g.bin))

    # textured_quad.gltf: indexed quad, normalized ushort UVs, ubyte vec4 colours, data-URI PNGs,
    # a sampler with every non-default mode, 16-bit grey normal map (linear), grey-alpha emissive.
    g = Gltf()
    pos = g.accessor([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], FLOAT, "VEC3", minmax=True)
    nrm = g.accessor([(0, 0, 1)] * 4, FLOAT, "VEC3")
    uv = g.accessor([(0, 65535), (65535, 65535), (65535, 0), (0, 0)], USHORT, "VEC2",
                    normalized=True)
    col = g.accessor([(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 255), (255, 255, 255, 0)],
                     UBYTE, "VEC4", normalized=True)
    idx = g.accessor([0, 1, 2, 0, 2, 3], UBYTE, "SCALAR")
    g.doc["meshes"] = [{"name": "quad", "primitives": [{
        "attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv, "COLOR_0": col},
        "indices": idx, "material": 0}]}]
    g.doc["images"] = [{"name": "checker", "uri": data_uri(PNG_RGB, "image/png")},
                       {"name": "grey16", "uri": data_uri(PNG_GREY16, "image/png")},
                       {"name": "grey_alpha", "uri": data_uri(PNG_GREY_ALPHA, "image/png")}]
    g.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9986, "wrapS": 33071, "wrapT": 33648},
                         {}]
    g.doc["textures"] = [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 1},
                         {"source": 2}]
    g.doc["materials"] = [{
        "name": "quad_material",
        "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1.0, 0.75],
                                 "baseColorTexture": {"index": 0},
                                 "metallicFactor": 0.25, "roughnessFactor": 0.75},
        "normalTexture": {"index": 1},
        "emissiveTexture": {"index": 2}, "emissiveFactor": [1.0, 0.5, 0.0],
        "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": True}]
    g.doc["nodes"] = [{"mesh": 0}]
    g.doc["scenes"] = [{"nodes": [0]}]
    write_json(VALID, "textured_quad.gltf", g.finish())

    # hierarchy.gltf: root TRS -> child matrix -> grandchild mesh; a second instance at the root.
    g = triangle_doc()
    s = math.sqrt(0.5)
    g.doc["nodes"] = [
        {"name": "root", "translation": [1, 2, 3], "rotation": [0, s, 0, s], "scale": [2, 2, 2],
         "children": [1]},
        {"name": "child", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1],
         "children": [2]},
        {"name": "leaf", "mesh": 0},
        {"name": "plain", "mesh": 0, "translation": [10, 0, 0]}]
    g.doc["scenes"] = [{"nodes": [0, 3]}]
    write_json(VALID, "hierarchy.gltf", g.finish())

    # strip_fan.gltf: a 5-vertex strip (3 triangles), a 5-vertex fan (3 triangles, non-indexed),
    # and points and lines primitives that are skipped with a warning.
    g = Gltf()
    strip_pos = g.accessor([(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0), (2, 0, 0)], FLOAT,
                           "VEC3", minmax=True)
    strip_idx = g.accessor([0, 1, 2, 3, 4], UINT, "SCALAR")
    fan_pos = g.accessor([(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1), (-1, 1, 1)], FLOAT,
                         "VEC3", minmax=True)
    g.doc["meshes"] = [{"primitives": [
        {"attributes": {"POSITION": strip_pos}, "indices": strip_idx, "mode": 5},
        {"attributes": {"POSITION": fan_pos}, "mode": 6},
        {"attributes": {"POSITION": fan_pos}, "mode": 0},
        {"attributes": {"POSITION": fan_pos}, "mode": 1}]}]
    g.doc["nodes"] = [{"mesh": 0}]
    g.doc["scenes"] = [{"nodes": [0]}]
    write_json(VALID, "strip_fan.gltf", g.finish())

    # camera.gltf: a perspective camera on a translated, rotated node; an orthographic one.
    g = triangle_doc()
    g.doc["cameras"] = [
        {"name": "persp", "type": "perspective",
         "perspective": {"yfov": math.radians(60), "znear": 0.05, "zfar": 100,
                         "aspectRatio": 1.5}},
        {"name": "ortho", "type": "orthographic",
         "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}]
    g.doc["nodes"] += [{"camera": 0, "translation": [0, 0, 5]}, {"camera": 1}]
    g.doc["scenes"] = [{"nodes": [0, 1, 2]}]
    write_json(VALID, "camera.gltf", g.finish())

    # lights.gltf: KHR_lights_punctual directional (rotated -90 deg about X: shines down -Y),
    # point (translated), spot (child of a translated parent, rotated 90 deg about Y: shines -X).
    g = triangle_doc()
    s = math.sqrt(0.5)
    g.doc["extensionsUsed"] = ["KHR_lights_punctual"]
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "sun", "type": "directional", "color": [1.0, 0.9, 0.8], "intensity": 3.0},
        {"name": "bulb", "type": "point", "intensity": 20.0, "range": 10.0},
        {"name": "torch", "type": "spot",
         "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.5}}]}}
    g.doc["nodes"] += [
        {"rotation": [-s, 0, 0, s], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"translation": [1, 2, 3], "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"translation": [0, 4, 0], "children": [4]},
        {"rotation": [0, s, 0, s], "extensions": {"KHR_lights_punctual": {"light": 2}}}]
    g.doc["scenes"] = [{"nodes": [0, 1, 2, 3]}]
    write_json(VALID, "lights.gltf", g.finish())

    # texture_transform.gltf: KHR_texture_transform (required) with offset, rotation, scale and
    # a texCoord override.
    g = triangle_doc()
    g.doc["meshes"][0]["primitives"][0]["material"] = 0
    g.doc["images"] = [{"uri": data_uri(PNG_RGB, "image/png")}]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {
        "index": 0, "extensions": {"KHR_texture_transform": {
            "offset": [0.5, 0.25], "rotation": math.pi / 2, "scale": [2, 3], "texCoord": 1}}}}}]
    g.doc["extensionsUsed"] = ["KHR_texture_transform"]
    g.doc["extensionsRequired"] = ["KHR_texture_transform"]
    write_json(VALID, "texture_transform.gltf", g.finish())

    # unlit.gltf: KHR_materials_unlit, KHR_materials_emissive_strength, BLEND; plus an unknown
    # optional extension (a warning).
    g = triangle_doc()
    g.doc["meshes"][0]["primitives"][0]["material"] = 0
    g.doc["materials"] = [{"name": "flat", "alphaMode": "BLEND", "emissiveFactor": [1, 0.5, 0.25],
                           "extensions": {"KHR_materials_unlit": {},
                                          "KHR_materials_emissive_strength":
                                              {"emissiveStrength": 4.0}}}]
    g.doc["extensionsUsed"] = ["KHR_materials_unlit", "KHR_materials_emissive_strength",
                               "EXT_made_up_optional"]
    write_json(VALID, "unlit.gltf", g.finish())

    # no_scenes.gltf: no "scenes": every root node is drawn (node 1 is a child of node 0).
    g = triangle_doc()
    g.doc["nodes"] = [{"mesh": 0, "children": [1]}, {"mesh": 0, "translation": [0, 0, -1]},
                      {"mesh": 0, "translation": [5, 0, 0]}]
    del g.doc["scenes"]
    del g.doc["scene"]
    write_json(VALID, "no_scenes.gltf", g.finish())

    # sparse.gltf: POSITION with a sparse override of vertex 2, and a colour accessor (VEC3
    # float) without a bufferView (all zeros).
    g = triangle_doc()
    sp_idx = g.view(struct.pack("<H", 2))
    sp_val = g.view(struct.pack("<3f", 0.0, 3.0, 0.0))
    g.doc["accessors"][0]["sparse"] = {"count": 1,
                                       "indices": {"bufferView": sp_idx, "componentType": USHORT},
                                       "values": {"bufferView": sp_val}}
    g.doc["accessors"][0]["max"] = [1.0, 3.0, 0.0]
    g.doc["accessors"].append({"componentType": FLOAT, "count": 3, "type": "VEC3"})
    g.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 2
    write_json(VALID, "sparse.gltf", g.finish())

    # triangle.glb: binary container, image stored in a bufferView of the BIN chunk.
    g = triangle_doc()
    g.doc["meshes"][0]["primitives"][0]["material"] = 0
    g.doc["images"] = [g.image_view(PNG_RGB, "image/png")]
    g.doc["textures"] = [{"source": 0}]
    g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc = g.finish(uri="")
    write_glb(VALID, "triangle.glb", doc, g.bin)

    # unsampled_maps.gltf: a base colour that decodes; a normal map that does not, an occlusion
    # map whose file is missing, and an image no material uses. focal's shading samples none of
    # the last three, so importing for any shading mode decodes only the base colour.
    g = triangle_doc()
    g.doc["meshes"][0]["primitives"][0]["material"] = 0
    g.doc["images"] = [{"name": "checker", "uri": data_uri(PNG_RGB, "image/png")},
                       {"name": "broken_normal",
                        "uri": data_uri(b"\x89PNG\r\n\x1a\nnot really a png", "image/png")},
                       {"uri": "missing_occlusion.png"},
                       {"name": "unused", "uri": data_uri(PNG_RGB, "image/png")}]
    g.doc["textures"] = [{"source": 0}, {"source": 1}, {"source": 2}, {"source": 3}]
    g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                    "metallicRoughnessTexture": {"index": 1}},
                           "normalTexture": {"index": 1},
                           "occlusionTexture": {"index": 2}}]
    write_json(VALID, "unsampled_maps.gltf", g.finish())


# --- malformed fixtures ----------------------------------------------------------------------

def make_bad():
    def tri():
        return triangle_doc()

    def save(name, doc):
        write_json(BAD, name, doc)

    os.makedirs(BAD, exist_ok=True)
    with open(os.path.join(BAD, "bad_json.gltf"), "w") as f:
        f.write('{"asset": {"version": "2.0"}, "nodes": [ {"mesh": 0,, } ]\n')
    with open(os.path.join(BAD, "not_gltf.gltf"), "wb") as f:
        f.write(b"\x00\x01\x02 this is not json")

    # Vertex index past the vertex count.
    g = Gltf()
    pos = g.accessor(TRI, FLOAT, "VEC3")
    idx = g.accessor([0, 1, 3], USHORT, "SCALAR")
    g.doc["meshes"] = [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}]
    g.doc["nodes"] = [{"mesh": 0}]
    g.doc["scenes"] = [{"nodes": [0]}]
    save("vertex_index_oob.gltf", g.finish())

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["material"] = 5
    save("material_oob.gltf", d)

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 3}}}]
    save("texture_oob.gltf", d)

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    d["textures"] = [{"source": 4}]
    save("image_oob.gltf", d)

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["materials"] = [{"emissiveTexture": {"index": 0}}]
    d["images"] = [{"uri": data_uri(PNG_RGB, "image/png")}]
    d["textures"] = [{"source": 0, "sampler": 2}]
    save("sampler_oob.gltf", d)

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9
    save("accessor_oob.gltf", d)

    d = tri().finish()
    d["accessors"][0]["bufferView"] = 7
    save("bufferview_oob.gltf", d)

    d = tri().finish()
    d["bufferViews"][0]["buffer"] = 3
    save("buffer_oob.gltf", d)

    d = tri().finish()
    d["nodes"][0]["children"] = [42]
    save("node_oob.gltf", d)

    d = tri().finish()
    d["nodes"][0]["mesh"] = 3
    save("mesh_oob.gltf", d)

    d = tri().finish()
    d["nodes"].append({"camera": 2})
    d["scenes"][0]["nodes"].append(1)
    save("camera_oob.gltf", d)

    d = tri().finish()
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["nodes"].append({"extensions": {"KHR_lights_punctual": {"light": 5}}})
    d["scenes"][0]["nodes"].append(1)
    save("light_oob.gltf", d)

    d = tri().finish()
    d["scene"] = 3
    save("default_scene_oob.gltf", d)

    # Accessor whose bufferView is in range but which reads past the whole buffer.
    d = tri().finish()
    d["accessors"][0]["count"] = 40
    save("accessor_past_buffer.gltf", d)

    # Accessor reading past its bufferView (but not past the buffer: the indices follow).
    d = tri().finish()
    d["accessors"][0]["byteOffset"] = 4
    save("accessor_past_view.gltf", d)

    # Strided reads: 3 vertices with byteStride 16 need 16*2+12 = 44 bytes; the view has 36.
    d = tri().finish()
    d["bufferViews"][0]["byteStride"] = 16
    save("accessor_stride_past_view.gltf", d)

    d = tri().finish()
    d["bufferViews"][1]["byteLength"] = 400
    save("view_past_buffer.gltf", d)

    d = tri().finish()
    d["accessors"][0]["type"] = "VEC2"
    save("position_wrong_type.gltf", d)

    d = tri().finish()
    d["accessors"][0]["componentType"] = USHORT
    save("position_wrong_component.gltf", d)

    d = tri().finish()
    d["accessors"][1]["componentType"] = FLOAT
    d["accessors"][1]["count"] = 1
    save("indices_wrong_type.gltf", d)

    g = triangle_doc()
    uv = g.accessor([(0, 0), (1, 0), (0, 1)], UBYTE, "VEC2")  # not normalized: not allowed
    g.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv
    save("texcoord_unnormalized_ubyte.gltf", g.finish())

    g = triangle_doc()
    nrm = g.accessor([(0, 0, 1), (0, 0, 1)], FLOAT, "VEC3")
    g.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = nrm
    save("normal_count_mismatch.gltf", g.finish())

    for name, bad in (("nan_position.gltf", float("nan")), ("inf_position.gltf", float("inf"))):
        g = Gltf()
        pos = g.accessor([(0, 0, 0), (1, bad, 0), (0, 1, 0)], FLOAT, "VEC3")
        g.doc["meshes"] = [{"primitives": [{"attributes": {"POSITION": pos}}]}]
        g.doc["nodes"] = [{"mesh": 0}]
        g.doc["scenes"] = [{"nodes": [0]}]
        save(name, g.finish())

    g = Gltf()
    pos = g.accessor(TRI + [(1, 1, 0)], FLOAT, "VEC3")
    idx = g.accessor([0, 1, 2, 3], USHORT, "SCALAR")
    g.doc["meshes"] = [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}]
    g.doc["nodes"] = [{"mesh": 0}]
    g.doc["scenes"] = [{"nodes": [0]}]
    save("indices_not_multiple_of_3.gltf", g.finish())

    save("missing_buffer.gltf", tri().finish(uri="missing.bin"))

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    d["images"] = [{"uri": "missing.png"}]
    d["textures"] = [{"source": 0}]
    save("missing_image.gltf", d)

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    d["images"] = [{"uri": data_uri(b"\x89PNG\r\n\x1a\nnot really a png", "image/png")}]
    d["textures"] = [{"source": 0}]
    save("undecodable_image.gltf", d)

    # A PNG whose header claims 100000 x 100000 pixels: refused before decoding.
    huge = bytearray(png(1, 1, 3, [0, 0, 0]))
    huge[16:24] = struct.pack(">II", 100000, 100000)
    d = tri().finish()
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    d["images"] = [{"uri": data_uri(bytes(huge), "image/png")}]
    d["textures"] = [{"source": 0}]
    save("huge_image.gltf", d)

    d = tri().finish()
    d["nodes"] = [{"mesh": 0}, {"children": [2]}, {"children": [1]}]
    save("node_cycle.gltf", d)

    d = tri().finish()
    d["nodes"][0]["children"] = [0]
    save("node_self_child.gltf", d)

    d = tri().finish()
    d["nodes"] = [{"children": [2]}, {"children": [2]}, {"mesh": 0}]
    d["scenes"] = [{"nodes": [0, 1]}]
    save("node_two_parents.gltf", d)

    d = tri().finish()
    d["nodes"] = [{"children": [1]}, {"mesh": 0}]
    d["scenes"] = [{"nodes": [0, 1]}]
    save("scene_lists_child.gltf", d)

    d = tri().finish()
    d["scenes"] = [{"nodes": []}]
    save("empty_scene.gltf", d)

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["mode"] = 0
    save("only_points.gltf", d)

    d = tri().finish()
    d["extensionsUsed"] = ["KHR_draco_mesh_compression"]
    d["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    save("required_extension.gltf", d)

    d = tri().finish()
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["materials"] = [{"alphaMode": "SOMETIMES"}]
    save("bad_alpha_mode.gltf", d)

    d = tri().finish()
    d["nodes"][0]["rotation"] = [0, 0, 0]
    save("bad_rotation.gltf", d)

    # Issue 23: hostile files. asset.extras nested 15,000 deep (30 KB; the recursive JSON
    # parser ran out of stack).
    with open(os.path.join(BAD, "deep_nesting.gltf"), "w") as f:
        f.write('{"asset": {"version": "2.0", "extras": ' + "[" * 15000 + "]" * 15000 + "}}\n")

    # 16 primitives reading accessors without a bufferView (zeros, which cost nothing in the
    # file): each is allowed, their sum is not (a 1.2 KB file asked for ~14 GB).
    d = tri().finish()
    n = 3 * 2 ** 17
    d["accessors"].append({"componentType": FLOAT, "count": n, "type": "VEC3"})
    zeros = len(d["accessors"]) - 1
    d["meshes"][0]["primitives"] = [{"attributes": {"POSITION": zeros}}] * 16
    save("zero_accessors_per_file.gltf", d)

    # A buffer uri naming a directory (was reported as "out of memory").
    d = tri().finish()
    d["buffers"][0]["uri"] = "."
    save("buffer_uri_directory.gltf", d)

    # A GLB cut short in the middle of its JSON chunk.
    g = triangle_doc()
    full = os.path.join(BAD, "truncated.glb")
    write_glb(BAD, "truncated.glb", g.finish(uri=""), g.bin)
    with open(full, "rb") as f:
        data = f.read()
    with open(full, "wb") as f:
        f.write(data[:60])


def make_fuzz_seeds():
    os.makedirs(FUZZ_SEEDS, exist_ok=True)

    def save(name, doc):
        # Python writes infinity as Infinity, which is not JSON; 1e999 is, and parses as it.
        text = json.dumps(doc, indent=1).replace("-Infinity", "-1e999")
        with open(os.path.join(FUZZ_SEEDS, name), "w") as f:
            f.write(text.replace("Infinity", "1e999") + "\n")

    # KHR_mesh_quantization: normalized SHORT positions, BYTE normals, UBYTE texcoords, BYTE
    # (unnormalized) positions of a second primitive, dequantized by the node's scale.
    g = Gltf()
    qpos = g.accessor([(0, 0, 0), (32767, 0, 0), (0, 32767, 0)], SHORT, "VEC3", normalized=True,
                      minmax=True)
    qnrm = g.accessor([(0, 0, 127)] * 3, BYTE, "VEC3", normalized=True)
    quv = g.accessor([(0, 0), (255, 0), (0, 255)], UBYTE, "VEC2", normalized=True)
    bpos = g.accessor([(0, 0, -1), (100, 0, -1), (0, 100, -1)], BYTE, "VEC3", minmax=True)
    idx = g.accessor([0, 1, 2], USHORT, "SCALAR")
    g.doc["extensionsUsed"] = ["KHR_mesh_quantization"]
    g.doc["extensionsRequired"] = ["KHR_mesh_quantization"]
    g.doc["meshes"] = [{"primitives": [
        {"attributes": {"POSITION": qpos, "NORMAL": qnrm, "TEXCOORD_0": quv}, "indices": idx},
        {"attributes": {"POSITION": bpos}}]}]
    g.doc["nodes"] = [{"mesh": 0, "scale": [0.01, 0.01, 0.01]}]
    g.doc["scenes"] = [{"nodes": [0]}]
    save("quantized.gltf", g.finish())
    doc = g.finish(uri="")
    write_glb(FUZZ_SEEDS, "quantized.glb", doc, g.bin)

    # Matrix accessors (MAT2/MAT3/MAT4, normalized 1-byte columns are padded) used as
    # attributes and as a skin's inverse bind matrices, and node matrices.
    g = triangle_doc()
    m4 = g.accessor([[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]] * 3, FLOAT, "MAT4")
    m2 = g.accessor([[1, 0, 0, 1]] * 3, UBYTE, "MAT2", normalized=True)
    g.doc["meshes"].append({"primitives": [{"attributes": {"POSITION": m4, "NORMAL": m2}}]})
    g.doc["skins"] = [{"joints": [0], "inverseBindMatrices": m4}]
    g.doc["nodes"][0]["matrix"] = [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 1, 2, 3, 1]
    g.doc["nodes"].append({"mesh": 1, "skin": 0})
    g.doc["scenes"] = [{"nodes": [0, 1]}]
    save("matrix_accessors.gltf", g.finish())

    # Non-finite numbers. JSON has none, and the parser refuses 1e999 (non_finite_json.gltf),
    # so they come from finite numbers that overflow: a node scale of 3e38 under which a mesh,
    # a camera and a light sit (world matrices of inf), 3e38 factors; and NaN in vertex data.
    g = triangle_doc()
    d = g.finish()
    d["nodes"] = [{"scale": [3e38, 3e38, 3e38], "children": [1, 2, 3]},
                  {"mesh": 0, "translation": [3e38, 0, 0]},
                  {"camera": 0, "translation": [0, 0, 3e38]},
                  {"extensions": {"KHR_lights_punctual": {"light": 0}}}]
    d["cameras"] = [{"type": "perspective", "perspective": {"yfov": 3.14159, "znear": 1e-38}}]
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 3e38,
                                                           "color": [3e38, 3e38, 3e38]}]}}
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorFactor": [3e38, 3e38, 0, 1]},
                       "emissiveFactor": [3e38, 0, 0]}]
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["scenes"] = [{"nodes": [0]}]
    save("non_finite.gltf", d)
    g = triangle_doc()
    d = g.finish()
    d["materials"] = [{"pbrMetallicRoughness": {"baseColorFactor": [1e999, 0, 0, 1],
                                                "metallicFactor": -1e999},
                       "emissiveFactor": [0, 1e999, 0], "alphaCutoff": 1e999}]
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["nodes"][0]["translation"] = [1e999, 0, 0]
    d["nodes"].append({"camera": 0, "rotation": [0, 0, 0, 1e999]})
    d["cameras"] = [{"type": "perspective",
                     "perspective": {"yfov": 1e999, "znear": 0.1, "zfar": 1e999}}]
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "spot", "intensity": 1e999,
                                                           "spot": {"outerConeAngle": 1e999}}]}}
    d["nodes"].append({"extensions": {"KHR_lights_punctual": {"light": 0}}})
    d["scenes"] = [{"nodes": [0, 1, 2]}]
    save("non_finite_json.gltf", d)
    g = Gltf()
    pos = g.accessor([(0, 0, 0), (math.nan, 0, 0), (0, math.inf, 0)], FLOAT, "VEC3")
    g.doc["meshes"] = [{"primitives": [{"attributes": {"POSITION": pos}}]}]
    g.doc["nodes"] = [{"mesh": 0}]
    g.doc["scenes"] = [{"nodes": [0]}]
    save("non_finite_positions.gltf", g.finish())


if __name__ == "__main__":
    make_valid()
    make_bad()
    make_fuzz_seeds()
