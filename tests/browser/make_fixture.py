#!/usr/bin/env python3
"""Writes a small `focal steps` folder (docs/steps-format.md, format 1) for a multiview frame,
without focal: made-up but well-formed stages, PNGs, probes and rays, so the page can be
developed and tested on its own. Usage: make_fixture.py OUT_DIR [PAGE_DIR]. With PAGE_DIR
(apps/steps_page), the page's three files are copied in too, as `focal steps` would write them.
"""
import json
import math
import os
import shutil
import struct
import sys
import zlib

W, H = 64, 48  # the frame's size in pixels
GRID = 16


def write_png(path, width, height, pixel):
    """pixel(x, y) -> (r, g, b, a) in 0..255; 8-bit RGBA, no filter."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        for x in range(width):
            raw.extend(pixel(x, y))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def scene_linear(x, y, blur):
    """A made-up scene in linear light: a red disc in front of a blue/green checker."""
    cx, cy = x + 0.5, y + 0.5
    checker = ((int(cx) // 8) + (int(cy) // 8)) % 2
    back = (0.05, 0.3 + 0.4 * checker, 0.8 - 0.5 * checker)
    d = math.hypot(cx - 24, cy - 20)
    edge = min(1.0, max(0.0, (14 - d) / max(blur, 0.5) + 0.5))
    return tuple(round(edge * f + (1 - edge) * b, 6) for f, b in zip((0.9, 0.1, 0.05), back))


def srgb8(v):
    v = min(1.0, max(0.0, v))
    s = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return int(round(s * 255))


def rgb_image(f):
    return lambda x, y: tuple(srgb8(c) for c in f(x, y)) + (255,)


def main():
    out = sys.argv[1]
    page = sys.argv[2] if len(sys.argv) > 2 else None
    img_dir = os.path.join(out, "images")
    os.makedirs(img_dir, exist_ok=True)

    def image(name, file, caption, f, width=W, height=H, scale=None):
        write_png(os.path.join(img_dir, file), width, height, f)
        rec = {"name": name, "file": "images/" + file, "width": width, "height": height,
               "caption": caption}
        if scale:
            rec["scale"] = scale
        return rec

    sharp = lambda x, y: scene_linear(x, y, 0.5)
    result = lambda x, y: scene_linear(x, y, 6.0)
    reference = lambda x, y: scene_linear(x, y, 6.5)
    depth = lambda x, y: 3.0 if math.hypot(x + 0.5 - 24, y + 0.5 - 20) < 14 else 8.0
    grey = lambda v: (v, v, v, 255)
    layer_of = lambda x, y: 0 if depth(x, y) < 5 else 2

    def layer_image(k):
        return lambda x, y: (tuple(srgb8(c) for c in sharp(x, y)) + (255,)) if layer_of(x, y) == k else (0, 0, 0, 0)

    stages = [
        {"id": "raster.coverage", "group": "raster", "title": "Tile raster", "paper": "",
         "text": "Triangles binned into 16x16 tiles, rasterized with the top-left rule.",
         "ms": 0.8, "counts": {"triangles_in": 12, "fragments": W * H},
         "images": [image("colour", "raster_color.png", "sRGB colour of the pinhole render", rgb_image(sharp)),
                    image("tile heat", "raster_tiles.png", "triangles per 16x16 tile", lambda x, y: grey(40 * ((x + y) % 5)),
                          W // 16, H // 16, 16)],
         "tables": [], "plots": []},
        {"id": "targets.depth", "group": "targets", "title": "Depth target", "paper": "",
         "text": "Linear depth along the view axis, 1/d mapped to grey.",
         "ms": None, "counts": {}, "images": [image("depth", "targets_depth.png", "white = near",
                                                     lambda x, y: grey(int(255 * 2.0 / depth(x, y))))],
         "tables": [], "plots": []},
        {"id": "multiview.layers", "group": "multiview", "title": "Layered decomposition",
         "paper": "Lee, Eisemann & Seidel 2009, §4.2 (Eq. 4)",
         "text": "The scene is split into layers uniform in signed CoC; each layer has its own depth buffer.",
         "ms": 2.5, "counts": {"layers": 3},
         "images": [image("layer %d colour" % k, "multiview_layer%02d_color.png" % k,
                          "sRGB colour, alpha = coverage", layer_image(k)) for k in range(3)],
         "tables": [{"name": "layer bounds", "columns": ["layer", "d_near", "d_far", "C_near px", "C_far px"],
                     "rows": [[0, 2.5, 4.0, -6.1, -2.0], [1, 4.0, 6.0, -2.0, 0.5], [2, 6.0, 9.0, 0.5, 2.8]]}],
         "plots": []},
        {"id": "multiview.nbuffer", "group": "multiview", "title": "N-buffer", "paper": "Lee et al. 2009, §4.3",
         "text": "Min/max depth pyramids used to skip empty layer regions.", "ms": 0.4, "counts": {"levels": 2},
         "images": [image("level 2 min depth", "multiview_nbuffer2.png", "4x4 frame pixels per texel",
                          lambda x, y: grey(int(255 * 2.0 / depth(4 * x, 4 * y))), W // 4, H // 4, 4)],
         "tables": [], "plots": []},
        {"id": "multiview.lens", "group": "multiview", "title": "Lens samples", "paper": "Lee et al. 2009, §5",
         "text": "Sample positions on the unit lens disk.", "ms": None, "counts": {"samples": 8},
         "images": [], "tables": [],
         "plots": [{"name": "lens samples", "kind": "points", "x_label": "u", "y_label": "v",
                    "x_range": [-1, 1], "y_range": [-1, 1],
                    "points": [[round(0.8 * math.cos(k * 0.785), 4), round(0.8 * math.sin(k * 0.785), 4)] for k in range(8)],
                    "labels": [str(k) for k in range(8)]}]},
        {"id": "multiview.rays", "group": "multiview", "title": "Ray traversal", "paper": "Lee et al. 2009, §5.1",
         "text": "Each lens ray walks the layers front to back until it hits.", "ms": 5.1,
         "counts": {"rays": W * H * 8, "misses": 31},
         "images": [image("result", "multiview_rays.png", "sRGB colour", rgb_image(result))],
         "tables": [], "plots": []},
        {"id": "result.final", "group": "result", "title": "Result", "paper": "",
         "text": "The method's image.", "ms": None, "counts": {},
         "images": [image("result", "result.png", "sRGB colour", rgb_image(result))], "tables": [], "plots": []},
    ]
    compare = {
        "result": "images/result.png",
        "reference": "images/reference.png",
        "difference": "images/difference.png",
        "reference_samples": 256, "psnr_db": 34.2, "ssim": 0.97,
        "caption": "difference: |result - reference| in sRGB, scaled x8",
    }
    write_png(os.path.join(img_dir, "reference.png"), W, H, rgb_image(reference))
    write_png(os.path.join(img_dir, "difference.png"), W, H, lambda x, y: grey(min(255, 8 * abs(
        srgb8(result(x, y)[0]) - srgb8(reference(x, y)[0])))))

    pixels = [(x, y) for y in range(GRID // 2, H, GRID) for x in range(GRID // 2, W, GRID)]
    pixels.append((30, 20))  # as if from --probe 30,20
    pixels.sort(key=lambda p: (p[1], p[0]))
    probes = []
    for x, y in pixels:
        rgba = list(result(x, y)) + [1.0]
        coc = 4.0 if depth(x, y) < 5 else 2.0
        rays = []
        for k in range(4):
            a = k * math.pi / 2
            end = [round(x + 0.5 + coc * math.cos(a), 3), round(y + 0.5 + coc * math.sin(a), 3)]
            rays.append({"lens": [round(math.cos(a), 4), round(math.sin(a), 4)], "weight": 0.25,
                         "layers": [0, 1, 2] if k % 2 else [0], "hit": k % 3, "rgba": rgba,
                         "_end": end})
        draw = [{"kind": "polyline", "points": [[x + 0.5, y + 0.5], r.pop("_end")], "label": "ray %d" % k,
                 "stages": ["multiview.rays", "multiview.layers"]} for k, r in enumerate(rays)]
        draw.append({"kind": "circle", "at": [x + 0.5, y + 0.5], "r": coc, "label": "CoC", "stages": ["multiview.layers"]})
        draw.append({"kind": "point", "at": [x + 0.5, y + 0.5], "label": "pixel", "stages": ["*"]})
        probes.append({"x": x, "y": y, "rgba": rgba, "reference_rgba": list(reference(x, y)) + [1.0],
                       "fragments": [{"depth": depth(x, y), "primitive": 3, "rgba": list(sharp(x, y)) + [1.0]}],
                       "method": {"rays": rays}, "draw": draw})

    data = {
        "format_version": 1, "focal_version": "fixture",
        "command": "focal steps builtin:demo --method multiview --width 64 --height 48 -o DIR",
        "probe_command": "focal probe builtin:demo X,Y --method multiview --width 64 --height 48",
        "scene": "builtin:demo", "method": "multiview", "width": W, "height": H,
        "stages": stages, "compare": compare, "probe_grid": GRID, "probes": probes,
    }
    text = json.dumps(data, indent=1)
    with open(os.path.join(out, "steps.json"), "w") as f:
        f.write(text + "\n")
    with open(os.path.join(out, "steps_data.js"), "w") as f:
        f.write("window.FOCAL_STEPS = " + text + ";\n")
    if page:
        for name in ("index.html", "steps.css", "steps.js"):
            shutil.copyfile(os.path.join(page, name), os.path.join(out, name))


if __name__ == "__main__":
    main()
