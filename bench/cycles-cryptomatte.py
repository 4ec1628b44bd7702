#!/usr/bin/env python3
"""rt's Cryptomatte (`--aov cryptomatte`) against Blender Cycles' (View Layer ▸ Passes ▸
Cryptomatte ▸ Object), per object and per pixel: a sphere, a box, a thin torus and a floor under a
camera that sees the background behind them, built in Blender's `bpy`, exported with its glTF
exporter and rendered by Cycles (CPU, 1-pixel box filter as rt's) and by rt from the .glb. For each
object (found by its name's id in both files, so the names hash alike): its total coverage (its
area in pixels) and the mean absolute difference of its per-pixel coverage over the pixels where
either renderer gives it some (the edges are where the two differ: jitter patterns differ).

Needs: Python 3.13 with `pip install bpy==5.2.3 OpenEXR`, and a release rt-cli.

Usage: python3.13 bench/cycles-cryptomatte.py [--spp 32] [--rt-spp 32] [--out DIR]
"""

import math
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

import bpy
from cycles_settings import add_camera, export_glb, match_rt, read_channels

ROOT = Path(__file__).resolve().parent.parent
CLI = ROOT / "target" / "release" / "rt-cli"
WIDTH, HEIGHT = 320, 240
NAMES = ("sphere", "box", "torus", "floor")


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=6, location=(0, 0, 0))
    bpy.context.object.name = "floor"
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(-1.0, 0, 0.8), segments=64,
                                         ring_count=32)
    bpy.ops.object.shade_smooth()
    bpy.context.object.name = "sphere"
    bpy.ops.mesh.primitive_cube_add(size=0.8, location=(0.9, 0.4, 0.4),
                                    rotation=(0, 0, math.radians(30)))
    bpy.context.object.name = "box"
    bpy.ops.mesh.primitive_torus_add(location=(0.2, -1.0, 0.9), major_radius=0.5,
                                     minor_radius=0.04, rotation=(math.radians(70), 0, 0))
    bpy.context.object.name = "torus"
    bpy.ops.object.light_add(type="SUN", rotation=(math.radians(30), 0, 0))
    add_camera(bpy, scene, (0.0, -6.0, 2.5), (0.0, 6.0, -1.8), 35)
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    return scene


def murmur3(name):
    """MurmurHash3 x86 32 of the name (as rt and Blender hash it)."""
    data = name.encode()
    h, c1, c2 = 0, 0xCC9E2D51, 0x1B873593
    rotl = lambda x, r: ((x << r) | (x >> (32 - r))) & 0xFFFFFFFF
    for i in range(0, len(data) // 4 * 4, 4):
        k = int.from_bytes(data[i:i + 4], "little")
        h ^= rotl(k * c1 & 0xFFFFFFFF, 15) * c2 & 0xFFFFFFFF
        h = (rotl(h, 13) * 5 + 0xE6546B64) & 0xFFFFFFFF
    tail = data[len(data) // 4 * 4:]
    if tail:
        k = int.from_bytes(tail, "little")
        h ^= rotl(k * c1 & 0xFFFFFFFF, 15) * c2 & 0xFFFFFFFF
    h ^= len(data)
    for shift, mul in ((16, 0x85EBCA6B), (13, 0xC2B2AE35), (16, None)):
        h ^= h >> shift
        if mul:
            h = h * mul & 0xFFFFFFFF
    return h


def id_of(name):
    h = murmur3(name)
    exponent = min(max((h >> 23) & 0xFF, 1), 254)
    bits = (h & 0x807FFFFF) | (exponent << 23)
    return struct.unpack("<f", struct.pack("<I", bits))[0]


def coverage_of(channels, prefix, name):
    """The object's coverage per pixel summed over the ranks."""
    import numpy

    want = numpy.float32(id_of(name))
    total = None
    for layer in range(3):
        for ident, cov in (("r", "g"), ("b", "a")):
            ids = channels[f"{prefix}CryptoObject{layer:02d}.{ident}"].astype(numpy.float32)
            c = channels[f"{prefix}CryptoObject{layer:02d}.{cov}"]
            part = numpy.where(ids == want, c, 0.0)
            total = part if total is None else total + part
    return total


def manifest(path):
    """The Cryptomatte manifest in the EXR's header (name → hex hash)."""
    import json

    import OpenEXR

    for part in OpenEXR.File(str(path)).parts:
        for key, value in part.header.items():
            if key.startswith("cryptomatte/") and key.endswith("/manifest"):
                return json.loads(value if isinstance(value, str) else value.decode())
    return {}


def main():
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--rt-spp", type=int, default=32)
    parser.add_argument("--out", default=tempfile.mkdtemp(prefix="rt-crypto-"))
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scene = build()
    export_glb(bpy, out / "scene.glb")
    match_rt(scene, args.spp, 2)
    scene.view_layers[0].use_pass_cryptomatte_object = True
    settings = scene.render.image_settings
    settings.media_type = "MULTI_LAYER_IMAGE"
    settings.color_depth = "32"
    scene.render.filepath = str(out / "cycles.exr")
    bpy.ops.render.render(write_still=True)
    rt = out / "rt.exr"
    subprocess.run([str(CLI), "render", "--device", "cpu", "--spp", str(args.rt_spp),
                    "--width", str(WIDTH), "--height", str(HEIGHT), "--max-depth", "2",
                    "--aov", "cryptomatte", "-o", str(rt), str(out / "scene.glb")],
                   check=True, stderr=subprocess.DEVNULL)
    cycles, ours = read_channels(out / "cycles.exr"), read_channels(rt)
    print(f"{WIDTH}x{HEIGHT}, Cycles {args.spp} spp, rt {args.rt_spp} spp (coverage over "
          f"min(spp, 32) rays); area in pixels, per-pixel |difference| where either covers")
    print(f"{'object':8} {'Cycles area':>12} {'rt area':>10} {'ratio':>7} {'mean |d|':>9} "
          f"{'pixels':>7}")
    theirs, mine = manifest(out / "cycles.exr"), manifest(rt)
    same = [n for n in NAMES if n in theirs and theirs.get(n) == mine.get(n)]
    print(f"manifest: {len(same)} of {len(NAMES)} names with the same hash in both "
          f"(Cycles lists {sorted(theirs)}, rt {sorted(mine)})")
    for name in NAMES:
        c = coverage_of(cycles, "ViewLayer.", name)
        r = coverage_of(ours, "", name)
        either = (c > 0) | (r > 0)
        diff = abs(c - r)[either].mean() if either.any() else 0.0
        print(f"{name:8} {c.sum():12.1f} {r.sum():10.1f} {r.sum() / max(c.sum(), 1e-9):7.4f} "
              f"{diff:9.4f} {either.sum():7d}")


if __name__ == "__main__":
    sys.exit(main())
