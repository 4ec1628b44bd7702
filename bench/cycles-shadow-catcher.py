#!/usr/bin/env python3
"""rt's shadow catcher against Blender Cycles' (Object ▸ Shadow Catcher on a transparent film),
per region of the catcher and per object: a grey floor that catches the shadows of a floating
white sphere and a red box standing on it, under a sun (no angle: a delta light in both) and a
uniform grey world, built in Blender's `bpy`, exported with its glTF exporter and rendered by
Cycles (CPU) and by rt from the .glb (`--shadow-catcher floor --ambient`). Cycles' object-index
pass marks the regions: the floor in the sphere's and the box's shadows and in the open, and the
two objects. Alpha is compared on the floor, colour on everything (on the floor that is the light
of the other objects it shows: the box's red bounce and the sphere's).

Needs: Python 3.13 with `pip install bpy==5.2.3 OpenEXR`, and a release rt-cli.

Usage: python3.13 bench/cycles-shadow-catcher.py [--spp 1024] [--rt-spp 1024] [--out DIR]
Writes OUT/scene.glb (OUT is a temporary folder unless given) and prints the comparison.
"""

import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import bpy
from cycles_settings import (
    add_camera,
    arguments,
    export_glb,
    read_channels,
    render_with_object_index,
)

ROOT = Path(__file__).resolve().parent.parent
CLI = ROOT / "target" / "release" / "rt-cli"
WIDTH, HEIGHT, DEPTH = 320, 240, 8
AMBIENT, SUN = 0.3, 3.0
SUN_TILT = 30.0


def principled(bpy, name, colour):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*colour, 1)
    bsdf.inputs["Roughness"].default_value = 1.0
    return m


def build(bpy):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
    floor = bpy.context.object
    floor.name = "floor"
    floor.data.materials.append(principled(bpy, "grey", (0.6, 0.6, 0.6)))
    floor.pass_index = 1
    floor.is_shadow_catcher = True
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-0.8, 0, 1.2), segments=96,
                                         ring_count=48)
    bpy.ops.object.shade_smooth()
    sphere = bpy.context.object
    sphere.name = "sphere"
    sphere.data.materials.append(principled(bpy, "white", (0.8, 0.8, 0.8)))
    sphere.pass_index = 2
    bpy.ops.mesh.primitive_cube_add(size=0.8, location=(0.9, 0.3, 0.4))
    box = bpy.context.object
    box.name = "box"
    box.data.materials.append(principled(bpy, "red", (0.8, 0.1, 0.05)))
    box.pass_index = 3
    bpy.ops.object.light_add(type="SUN", rotation=(math.radians(SUN_TILT), 0,
                                                   math.radians(-20)))
    sun = bpy.context.object.data
    sun.energy = SUN
    sun.angle = 0.0
    add_camera(bpy, scene, (0.0, -6.0, 3.5), (0.0, 6.0, -3.2), 35)
    world = bpy.data.worlds.new("grey")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (AMBIENT,) * 3 + (1,)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    return scene


def rgba_of(channels):
    import numpy

    for prefix in ("", "ViewLayer.Combined."):
        if all(prefix + c in channels for c in "RGBA"):
            return numpy.stack([channels[prefix + c] for c in "RGBA"], axis=-1)
    for prefix in ("", "ViewLayer.Combined."):
        if all(prefix + c in channels for c in "RGB"):
            rgb = [channels[prefix + c] for c in "RGB"]
            return numpy.stack(rgb + [numpy.ones_like(rgb[0])], axis=-1)
    raise SystemExit(f"no RGB channels among {sorted(channels)}")


def inner(mask):
    """The mask less its edge pixels."""
    import numpy

    kept = mask.copy()
    for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        kept &= numpy.roll(mask, (dy, dx), axis=(0, 1))
    return kept


def render_rt(glb, out, spp, extra):
    run = subprocess.run([str(CLI), "render", str(glb), "--width", str(WIDTH), "--height",
                          str(HEIGHT), "--max-depth", str(DEPTH), "--spp", str(spp),
                          "--environment", "none", "--ambient", f"{AMBIENT},{AMBIENT},{AMBIENT}",
                          "--seed", "7", "-o", str(out), *extra],
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(run.stderr)
    return rgba_of(read_channels(out))


def cycles_variants(bpy, scene, spp, tmp):
    """Cycles' catcher render (RGBA), its truth (the floor an ordinary object, opaque film) and
    its photo (the floor alone, opaque), and the object-index pass."""
    render_with_object_index(bpy, scene, spp, DEPTH, tmp / "catcher.exr", rgba=True)
    channels = read_channels(tmp / "catcher.exr")
    index = next(v for k, v in channels.items() if "Index" in k)
    catcher = rgba_of(channels)
    scene.render.film_transparent = False
    bpy.data.objects["floor"].is_shadow_catcher = False
    render_with_object_index(bpy, scene, spp, DEPTH, tmp / "truth.exr")
    truth = rgba_of(read_channels(tmp / "truth.exr"))
    for name in ("sphere", "box"):
        bpy.data.objects[name].hide_render = True
    render_with_object_index(bpy, scene, spp, DEPTH, tmp / "photo.exr")
    photo = rgba_of(read_channels(tmp / "photo.exr"))
    return catcher, truth, photo, index


def main():
    args = arguments(__doc__, 1024, Path(tempfile.mkdtemp(prefix="rt-catcher-")))
    import numpy

    out = Path(args.out)
    scene = build(bpy)
    export_glb(bpy, out / "scene.glb")
    for obj in bpy.data.objects:
        obj.select_set(obj.name not in ("sphere", "box"))
    bpy.ops.export_scene.gltf(filepath=str(out / "floor.glb"), export_format="GLB",
                              export_lights=True, export_cameras=True, export_yup=True,
                              use_selection=True)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        c_catcher, c_truth, c_photo, index = cycles_variants(bpy, scene, args.spp, Path(tmp))
    t_cycles = time.perf_counter() - started
    started = time.perf_counter()
    r_catcher = render_rt(out / "scene.glb", out / "rt.exr", args.rt_spp,
                          ["--shadow-catcher", "floor"])
    t_rt = time.perf_counter() - started
    r_truth = render_rt(out / "scene.glb", out / "rt-truth.exr", args.rt_spp, [])
    r_photo = render_rt(out / "floor.glb", out / "rt-photo.exr", args.rt_spp, [])
    print(f"Blender {bpy.app.version_string} Cycles CPU, {args.spp} spp (catcher render "
          f"and two more): {t_cycles:.1f} s; rt {args.rt_spp} spp catcher render: {t_rt:.1f} s")
    # Each renderer's catcher over its own photo of the empty floor: colour + (1 − α) · photo,
    # which should be its render of the objects on an ordinary floor.
    composite = {
        "rt": r_catcher[..., :3] + (1.0 - r_catcher[..., 3:]) * r_photo[..., :3],
        "Cycles": c_catcher[..., :3] + (1.0 - c_catcher[..., 3:]) * c_photo[..., :3],
    }
    truth = {"rt": r_truth[..., :3], "Cycles": c_truth[..., :3]}
    floor = inner(numpy.abs(index - 1) < 0.5)
    alpha_c = c_catcher[..., 3]
    regions = {
        "floor, all": floor,
        "in shadow (Cycles α > 0.5)": floor & (alpha_c > 0.5),
        "half shadow (0.1 < α ≤ 0.5)": floor & (alpha_c > 0.1) & (alpha_c <= 0.5),
        "in the open (α ≤ 0.1)": floor & (alpha_c <= 0.1),
    }
    print("| catcher region (pixels) | α rt / Cycles | colour (G) rt / Cycles "
          "| composite / truth − 1 (G): rt, Cycles | rt composite / Cycles truth − 1 (G) |")
    print("| --- | --- | --- | --- | --- |")
    for name, mask in regions.items():
        g = {k: (composite[k][mask][:, 1].mean(), truth[k][mask][:, 1].mean())
             for k in composite}
        print(f"| {name} ({mask.sum()}) | {r_catcher[mask][:, 3].mean():.4f} / "
              f"{c_catcher[mask][:, 3].mean():.4f} | {r_catcher[mask][:, 1].mean():.4f} / "
              f"{c_catcher[mask][:, 1].mean():.4f} | "
              f"{100 * (g['rt'][0] / g['rt'][1] - 1):+.2f}%, "
              f"{100 * (g['Cycles'][0] / g['Cycles'][1] - 1):+.2f}% | "
              f"{100 * (g['rt'][0] / g['Cycles'][1] - 1):+.2f}% |")
    print("| object (pixels) | rt R/G/B | Cycles R/G/B | rt / Cycles − 1 |")
    print("| --- | --- | --- | --- |")
    for k, name in ((2, "sphere"), (3, "box")):
        mask = inner(numpy.abs(index - k) < 0.5)
        a, b = r_catcher[mask].mean(axis=0), c_catcher[mask].mean(axis=0)
        print(f"| {name} ({mask.sum()}) | {a[0]:.4f} / {a[1]:.4f} / {a[2]:.4f} | "
              f"{b[0]:.4f} / {b[1]:.4f} / {b[2]:.4f} | "
              + " / ".join(f"{100 * (x / y - 1):+.1f}%" for x, y in zip(a[:3], b[:3])) + " |")
    sky = index < 0.5
    print(f"background: rt α {r_catcher[sky][:, 3].mean():.4f}, "
          f"Cycles α {c_catcher[sky][:, 3].mean():.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
