#!/usr/bin/env python3
"""Writes examples/golden/two_planes.gltf (python3 standard library only): a red quad 2 m from
the camera, in focus, in front of a checker of green and blue quads 6 m away, all unlit
(KHR_materials_unlit), and a perspective camera. Small enough to read; the golden example
(examples/golden/CMakeLists.txt) blurs it with depth of field.

Run from anywhere: python3 examples/golden/make_scene.py
"""
import base64
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def quad(x0, y0, x1, y1, z):
    return [(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)]


# (corners, material): the near red square, then a 4x3 checker behind it.
quads = [(quad(-0.5, -0.5, 0.5, 0.5, -2.0), 0)]
for j in range(3):
    for i in range(4):
        quads.append((quad(-4.0 + 2 * i, -3.0 + 2 * j, -2.0 + 2 * i, -1.0 + 2 * j, -6.0), 1 + (i + j) % 2))

doc = {
    "asset": {"version": "2.0", "generator": "focal examples/golden/make_scene.py"},
    "extensionsUsed": ["KHR_materials_unlit"],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": c}, "extensions": {"KHR_materials_unlit": {}},
                   "doubleSided": True}
                  for c in ([0.9, 0.1, 0.05, 1.0], [0.1, 0.7, 0.2, 1.0], [0.1, 0.2, 0.8, 1.0])],
    "buffers": [], "bufferViews": [], "accessors": [], "meshes": [],
    "nodes": [{"camera": 0}],
    "cameras": [{"type": "perspective",
                 "perspective": {"yfov": 0.9, "znear": 0.1, "zfar": 50.0, "aspectRatio": 4 / 3}}],
}
data = bytearray()
for corners, material in quads:
    pos = struct.pack("<12f", *[c for v in corners for c in v])
    idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    for blob, ctype, atype, count in ((pos, 5126, "VEC3", 4), (idx, 5123, "SCALAR", 6)):
        while len(data) % 4:
            data.append(0)
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(data), "byteLength": len(blob)})
        data += blob
        acc = {"bufferView": len(doc["bufferViews"]) - 1, "componentType": ctype, "count": count, "type": atype}
        if atype == "VEC3":
            acc["min"] = [min(v[k] for v in corners) for k in range(3)]
            acc["max"] = [max(v[k] for v in corners) for k in range(3)]
        doc["accessors"].append(acc)
    a = len(doc["accessors"])
    doc["meshes"].append({"primitives": [{"attributes": {"POSITION": a - 2}, "indices": a - 1,
                                          "material": material}]})
    doc["nodes"].append({"mesh": len(doc["meshes"]) - 1})
doc["buffers"].append({"byteLength": len(data),
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode()})
doc["scenes"] = [{"nodes": list(range(len(doc["nodes"])))}]
doc["scene"] = 0
with open(os.path.join(HERE, "two_planes.gltf"), "w") as f:
    json.dump(doc, f, indent=1)
    f.write("\n")
