"""Renders the Cornell box (assets/cornell) with Blender Cycles on the CPU, as `mitsuba-vs-rt.py`
renders it with Mitsuba and rt: SIZE x SIZE, SPP samples, max depth 8 (every Cycles bounce limit
at 7), a 1-pixel box filter, no adaptive sampling, denoising or clamping (`cycles_settings`).
The light emits from its front face only, as in rt and Mitsuba (Cycles' emission is two-sided:
its back face is the plain diffuse surface); the world is black. Renders one sample first (Cycles
loads its kernels), then times the render itself and writes the linear image.

Needs Python 3.13 with `pip install bpy==5.2.3`.

Usage: python3.13 bench/cycles_cornell.py OUT.exr [--size 512] [--spp 256]
Prints: `cycles render time: SECONDS`
"""

import argparse
import json
from pathlib import Path

import bpy

from cornell_scene import parse_cornell
from cycles_settings import camera_and_world, match_rt, square_exr_film, timed_render

ROOT = Path(__file__).resolve().parent.parent
DEPTH = 8


def material(name, kd, ke):
    """A Lambertian of `kd`, emitting `ke` from its front face when `ke` is not black."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*kd, 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0
    if not any(ke):
        links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
        return mat
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*ke, 1.0)
    emission.inputs["Strength"].default_value = 1.0
    front = nodes.new("ShaderNodeAddShader")
    links.new(emission.outputs["Emission"], front.inputs[0])
    links.new(diffuse.outputs["BSDF"], front.inputs[1])
    geometry = nodes.new("ShaderNodeNewGeometry")
    mix = nodes.new("ShaderNodeMixShader")
    links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
    links.new(front.outputs["Shader"], mix.inputs[1])
    links.new(diffuse.outputs["BSDF"], mix.inputs[2])
    links.new(mix.outputs["Shader"], out.inputs["Surface"])
    return mat


def build(size, spp):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    folder = ROOT / "assets" / "cornell"
    vertices, objects, mtl = parse_cornell(folder)
    for i, obj in enumerate(objects):
        used = sorted({v for f in obj["faces"] for v in f})
        remap = {v: k for k, v in enumerate(used)}
        mesh = bpy.data.meshes.new(f"mesh{i}")
        mesh.from_pydata([vertices[v] for v in used], [],
                         [[remap[v] for v in f] for f in obj["faces"]])
        mesh.update()
        m = mtl.get(obj["material"], {})
        mesh.materials.append(material(f"mat{i}", m.get("Kd", [0, 0, 0]), m.get("Ke", [0, 0, 0])))
        ob = bpy.data.objects.new(obj["name"], mesh)
        scene.collection.objects.link(ob)
    camera_json = json.loads((folder / "cornell.json").read_text())
    camera_and_world(bpy, scene, camera_json, [0.0, 0.0, 0.0])
    square_exr_film(scene, size)
    match_rt(scene, spp, DEPTH)
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--spp", type=int, default=256)
    args = parser.parse_args()
    scene = build(args.size, args.spp)
    timed_render(bpy, scene, args.spp, args.out)


if __name__ == "__main__":
    main()
