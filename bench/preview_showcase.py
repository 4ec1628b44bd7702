"""The raster preview against the path tracer, per object, on a Blender-exported showcase.

Builds issue 44's kind of scene in Blender (bpy) and exports it as glTF: a gold sphere, a red
plastic sphere, a brushed-aluminium can, two blue boxes, an emissive lamp and a black-and-white
checkered floor under a point light and a sun (`--lights all|point|sun|lamp`), or a gold sphere
alone under the sun (`--lights solo`). Then renders it with `rt-cli render --device cpu --aov
object` (the path tracer, which also says which object each pixel shows) and `rt-cli preview`,
and prints each object's mean preview / render per channel; `--max-depth 2` compares the direct
light alone (the preview leaves its bounce light out at that depth).

Needs Python 3.13 with `pip install bpy==5.2.3`, numpy and OpenEXR, and a release rt-cli.

Usage: python3.13 bench/preview_showcase.py [--lights all] [--rt target/release/rt-cli]
       [--spp 256] [--max-depth 8] [--terms] [--keep FOLDER]
"""

import argparse
import math
import subprocess
import tempfile
from pathlib import Path

import bpy
import numpy
import OpenEXR

ROOT = Path(__file__).resolve().parent.parent


def material(name, base, metallic=0.0, rough=0.5, emission=None, strength=0.0, aniso=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = (*base, 1)
    b.inputs["Metallic"].default_value = metallic
    b.inputs["Roughness"].default_value = rough
    b.inputs["Anisotropic"].default_value = aniso
    if emission:
        b.inputs["Emission Color"].default_value = (*emission, 1)
        b.inputs["Emission Strength"].default_value = strength
    return m


def checker_floor(folder):
    image = bpy.data.images.new("checker", 256, 256)
    pixels = []
    for y in range(256):
        for x in range(256):
            c = 0.9 if ((x // 32) + (y // 32)) % 2 == 0 else 0.05
            pixels += [c, c, c if c > 0.5 else 0.2, 1]
    image.pixels = pixels
    image.filepath_raw = str(folder / "checker.png")
    image.file_format = "PNG"
    image.save()
    m = material("floor", (1, 1, 1), rough=0.8)
    tex = m.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = bpy.data.images.load(str(folder / "checker.png"))
    m.node_tree.links.new(tex.outputs["Color"], m.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    return m


def build(lights, folder):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene

    def add(m):
        bpy.context.object.data.materials.append(m)

    def sphere(location, radius=1.0):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, location=location, segments=48, ring_count=24)
        bpy.ops.object.shade_smooth()

    if lights == "solo":
        sphere((0, 0, 1))
        add(material("gold", (1.0, 0.766, 0.336), metallic=1.0, rough=0.25))
    else:
        bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
        add(checker_floor(folder))
        sphere((-2.5, 0, 1))
        add(material("gold", (1.0, 0.766, 0.336), metallic=1.0, rough=0.25))
        sphere((0, -1, 1))
        add(material("red plastic", (0.8, 0.05, 0.05), rough=0.3))
        bpy.ops.mesh.primitive_cylinder_add(radius=0.6, depth=2, location=(2.5, 0, 1))
        bpy.ops.object.shade_smooth()
        add(material("aluminium", (0.91, 0.92, 0.92), metallic=1.0, rough=0.35, aniso=0.8))
        for location in [(1, 2.5, 0.5), (-1.5, 2.5, 0.5)]:
            bpy.ops.mesh.primitive_cube_add(size=1, location=location)
            add(material("blue", (0.05, 0.15, 0.7), rough=0.6))
        sphere((0, 1, 3), 0.3)
        glow = 10.0 if lights in ("all", "lamp") else 0.0
        add(material("lamp", (1, 1, 1), emission=(1.0, 0.6, 0.2), strength=glow))
        if lights in ("all", "point"):
            bpy.ops.object.light_add(type="POINT", location=(3, -3, 4))
            bpy.context.object.data.energy = 1000
    if lights in ("all", "sun", "solo"):
        bpy.ops.object.light_add(type="SUN", rotation=(math.radians(40), 0, math.radians(30)))
        bpy.context.object.data.energy = 3
    bpy.ops.object.camera_add(location=(0, -9, 4.5), rotation=(math.radians(68), 0, 0))
    scene.camera = bpy.context.object
    path = folder / "showcase.glb"
    bpy.ops.export_scene.gltf(filepath=str(path), export_lights=True, export_cameras=True)
    return path


def read(path):
    with OpenEXR.File(str(path)) as f:
        return {k: numpy.asarray(v.pixels, dtype=numpy.float64) for k, v in f.channels().items()}


def render_pair(rt, glb, folder, spp, depth):
    """The path tracer's and the preview's images of `glb` at `depth`, and the object ids."""
    size = ["--width", "320", "--height", "240"]
    render, preview = folder / f"render-{depth}.exr", folder / f"preview-{depth}.exr"
    subprocess.run([rt, "render", "--device", "cpu", str(glb), *size, "--spp", str(spp),
                    "--max-depth", str(depth), "--aov", "object", "-o", str(render)],
                   check=True, capture_output=True)
    subprocess.run([rt, "preview", str(glb), *size, "--max-depth", str(depth), "-o", str(preview)],
                   check=True, capture_output=True)
    r, p = read(render), read(preview)
    rgb = lambda image: image.get("RGB", image.get("RGBA"))[..., :3]
    return rgb(r), rgb(p), r["object.ID"].astype(int)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lights", choices=["all", "point", "sun", "lamp", "solo"], default="all")
    parser.add_argument("--rt", default=str(ROOT / "target" / "release" / "rt-cli"))
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--max-depth", type=int, default=8)
    parser.add_argument("--terms", action="store_true",
                        help="also compare the direct light (depth 2) and the bounce light (the "
                             "difference between --max-depth and 2) on their own")
    parser.add_argument("--keep", type=Path, help="a folder to keep the scene and the images in")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        glb = build(args.lights, folder)
        full = render_pair(args.rt, glb, folder, args.spp, args.max_depth)
        direct = render_pair(args.rt, glb, folder, args.spp, 2) if args.terms else None
        info = subprocess.run([args.rt, "info", str(glb)], check=True, capture_output=True, text=True)
        if args.keep:
            args.keep.mkdir(parents=True, exist_ok=True)
            for kept in folder.iterdir():
                if kept.suffix in (".glb", ".exr"):
                    (args.keep / kept.name).write_bytes(kept.read_bytes())
    names = [line.split()[0] for line in info.stdout.splitlines() if line.startswith("  ")]
    ids = full[2]
    heading = f"lights {args.lights}, max depth {args.max_depth}: preview / render per object (R, G, B)"
    print(heading + ("; then direct (depth 2) and bounce (the rest)" if direct else ""))
    for o in sorted(set(ids.flatten())):
        mask = ids == o
        if o == 0 or mask.sum() < 30:
            continue
        ratio = lambda r, p: numpy.round(p[mask].mean(axis=0) / numpy.maximum(r[mask].mean(axis=0), 1e-9), 3)
        name = names[o - 1] if o - 1 < len(names) else str(o)
        line = f"  {name:12} {mask.sum():6} px  {ratio(full[0], full[1])}"
        if direct:
            bounce_r, bounce_p = full[0] - direct[0], full[1] - direct[1]
            line += f"  direct {ratio(direct[0], direct[1])}  bounce {ratio(bounce_r, bounce_p)}"
        print(line)


if __name__ == "__main__":
    main()
