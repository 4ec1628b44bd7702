"""Blender's own view transforms applied to known linear colours, for rt's display tests.

Writes a strip of linear colours through Blender's AgX and Standard views and its White Balance
(default tint 10) to 16-bit PNGs, reads them back, and prints the display values as JSON; the
numbers in crates/core/src/display.rs's tests come from this (Blender 5.2.3).

    python3.13 bench/blender_view_transforms.py [OUT_DIR]
"""
import json
import os
import sys

import bpy

OUT = sys.argv[1] if len(sys.argv) > 1 else "/tmp/rt-blender-view"
GREYS = [0.0, 0.01, 0.05, 0.18, 0.5, 1.0, 2.0, 4.0, 16.0, 64.0]
COLOURS = [(v, v, v) for v in GREYS] + [
    (0.5, 0.05, 0.02),
    (4.0, 0.4, 0.1),
    (64.0, 0.0, 0.0),
    (0.05, 0.2, 0.8),
]
VIEWS = [
    ("agx", "AgX", None),
    ("standard", "Standard", None),
    ("standard_wb3200", "Standard", 3200.0),
    ("standard_wb6500", "Standard", 6500.0),
    ("standard_wb10000", "Standard", 10000.0),
]


def main():
    os.makedirs(OUT, exist_ok=True)
    strip = bpy.data.images.new("strip", width=len(COLOURS), height=1, float_buffer=True)
    strip.pixels = [v for c in COLOURS for v in (*c, 1.0)]
    scene = bpy.context.scene
    settings = scene.view_settings
    result = {"colours": COLOURS}
    for name, transform, kelvin in VIEWS:
        settings.view_transform = transform
        settings.look = "None"
        settings.exposure = 0.0
        settings.gamma = 1.0
        settings.use_white_balance = kelvin is not None
        if kelvin is not None:
            settings.white_balance_temperature = kelvin
            settings.white_balance_tint = 10.0
        scene.render.image_settings.file_format = "PNG"
        scene.render.image_settings.color_depth = "16"
        path = os.path.join(OUT, f"{name}.png")
        strip.save_render(path, scene=scene)
        shown = bpy.data.images.load(path)
        shown.colorspace_settings.name = "Non-Color"
        p = list(shown.pixels)
        result[name] = [[round(p[4 * i + c], 4) for c in range(3)] for i in range(len(COLOURS))]
    print(json.dumps(result))


main()
