"""Renders an OBJ scene of rt's bench (e.g. `bench/scenes/glass-caustics`) with Blender Cycles on
the CPU, matched to rt as `cycles_cornell.py` is (`cycles_settings.match_rt`: max depth 8, 1-px box
filter, no adaptive sampling, denoising or clamping). Its MTL is read as rt reads the subset these
scenes use: `Kd` a Lambertian; `Ke` a one-sided emitter (back face: the Lambertian); `illum 3` a
mirror of `Ks` (Cycles' GGX at roughness 0, where rt's fuzz from `Ns` 100000 is 0.0045: the
difference is far below the noise); `illum 7` smooth glass of index `Ni`. The camera file is rt's
(`--camera`: from, to, up, vertical fov, and `background`, the radiance of rays that leave the
scene, which becomes the world's colour). Vertex normals (`vn`) shade smoothly, as in rt.

Needs Python 3.13 with `pip install bpy==5.2.3`.

Checked on glass-caustics at 128² (2026-12-06): image means 1.0015 of rt's, region by region
alike; that check found rt rendering the glass ball inside-out, since fixed (its faces wind inward,
its normals point out: rt now orients a triangle by its normals, `crates/core/tests/winding.rs`).

Usage: python3.13 bench/cycles_obj.py SCENE.obj CAMERA.json OUT.exr [--size 256] [--spp 128]
Prints: `cycles render time: SECONDS` (after a one-sample render that loads the kernels)
"""

import argparse
import json
from pathlib import Path

import bpy
import mathutils

from cycles_cornell import material as lambert_or_emitter
from cycles_settings import camera_and_world, match_rt, square_exr_film, timed_render

DEPTH = 8


def read_mtl(path):
    materials, current = {}, None
    for line in path.read_text().splitlines():
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        if parts[0] == "newmtl":
            current = materials.setdefault(parts[1], {})
        elif current is not None:
            current[parts[0]] = [float(v) for v in parts[1:]]
    return materials


def single_bsdf(name, node_type, inputs):
    """A material of one BSDF node of `node_type` with these input values."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    bsdf = nodes.new(node_type)
    for key, value in inputs.items():
        bsdf.inputs[key].default_value = value
    mat.node_tree.links.new(bsdf.outputs["BSDF"],
                            nodes.new("ShaderNodeOutputMaterial").inputs["Surface"])
    return mat


def cycles_material(name, m):
    illum = m.get("illum", [0])[0]
    if illum == 7:
        # GGX at roughness 0 is Cycles' smooth glass.
        return single_bsdf(name, "ShaderNodeBsdfGlass", {
            "Roughness": 0.0, "IOR": m.get("Ni", [1.5])[0],
            "Color": (*m.get("Tf", [1, 1, 1]), 1.0)})
    if illum == 3:
        return single_bsdf(name, "ShaderNodeBsdfGlossy", {
            "Roughness": 0.0, "Color": (*m.get("Ks", [1, 1, 1]), 1.0)})
    return lambert_or_emitter(name, m.get("Kd", [0, 0, 0]), m.get("Ke", [0, 0, 0]))


def build(obj_path, camera_path, size, spp):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    materials = {}
    positions, normals, objects = [], [], []
    for line in obj_path.read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "mtllib":
            materials = read_mtl(obj_path.parent / parts[1])
        elif parts[0] == "v":
            positions.append([float(v) for v in parts[1:4]])
        elif parts[0] == "vn":
            normals.append([float(v) for v in parts[1:4]])
        elif parts[0] == "o":
            objects.append({"name": parts[1], "faces": [], "material": None})
        elif parts[0] == "usemtl":
            if not objects:
                objects.append({"name": parts[1], "faces": [], "material": None})
            objects[-1]["material"] = parts[1]
        elif parts[0] == "f":
            corners = [p.split("/") for p in parts[1:]]
            objects[-1]["faces"].append(
                [(int(c[0]) - 1, int(c[2]) - 1 if len(c) > 2 and c[2] else None) for c in corners])
    for i, obj in enumerate(objects):
        # A face whose winding disagrees with its vertex normals is turned over: Cycles darkens a
        # shading normal on the far side of the geometric one, where rt follows the normals.
        for f in obj["faces"]:
            if all(n is not None for _, n in f) and len(f) >= 3:
                a, b, c = (mathutils.Vector(positions[v]) for v, _ in f[:3])
                average = sum((mathutils.Vector(normals[n]) for _, n in f), mathutils.Vector())
                if (b - a).cross(c - a).dot(average) < 0.0:
                    f.reverse()
        used = sorted({v for f in obj["faces"] for v, _ in f})
        remap = {v: k for k, v in enumerate(used)}
        mesh = bpy.data.meshes.new(f"mesh{i}")
        mesh.from_pydata([positions[v] for v in used], [],
                         [[remap[v] for v, _ in f] for f in obj["faces"]])
        mesh.update()
        if normals and all(n is not None for f in obj["faces"] for _, n in f):
            # These scenes give each position one normal (spheres): set them per vertex.
            per_vertex = [(0.0, 0.0, 1.0)] * len(used)
            for f in obj["faces"]:
                for v, n in f:
                    per_vertex[remap[v]] = tuple(normals[n])
            mesh.shade_smooth()
            mesh.normals_split_custom_set_from_vertices(per_vertex)
        m = materials.get(obj["material"], {})
        mesh.materials.append(cycles_material(f"mat{i}", m))
        scene.collection.objects.link(bpy.data.objects.new(obj["name"], mesh))
    camera_json = json.loads(camera_path.read_text())
    camera_and_world(bpy, scene, camera_json, camera_json.get("background", [0, 0, 0]))
    square_exr_film(scene, size)
    match_rt(scene, spp, DEPTH)
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", type=Path)
    parser.add_argument("camera", type=Path)
    parser.add_argument("out")
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--spp", type=int, default=128)
    args = parser.parse_args()
    scene = build(args.scene, args.camera, args.size, args.spp)
    timed_render(bpy, scene, args.spp, args.out)


if __name__ == "__main__":
    main()
