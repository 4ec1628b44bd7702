#!/usr/bin/env python3
"""rt's participating media against Mitsuba 3's `volpath`: writes a small glTF scene, renders
Mitsuba's references of it at high spp, with and without fog, and compares rt's renders (image
means, 32-px blocks, each object's own pixels).

The scene (y up): a grey floor, a square area light above it facing down, a ball of a chromatic
scattering volume and a slab of a forward-scattering one lying on the floor, both behind
index-matched boundaries (no refraction, no reflection), and in front a dense one behind a smooth
boundary of index 1.4 (subsurface scattering: rt's test renders it from `Pbr::subsurface`, which
maps onto the same medium). Matched per object:
  floor   glTF base 0.5, roughness 1, KHR_materials_specular 0   Mitsuba diffuse 0.5
  light   emissive 1 x KHR_materials_emissive_strength 2        area, radiance 2 (front face),
          2 x 2, 2.4 above the floor
  ball    transmission 1, IOR 1, KHR_materials_volume            null BSDF, interior homogeneous:
          (attenuation colour C at distance D) and the draft      sigma_t = -ln(C)/D, albedo = the
          KHR_materials_volume_scatter (multiscatterColor M,      single-scattering albedo of M
          scatterAnisotropy G)                                    (rt_core::math::medium's
                                                                  inversion), hg g = G
  slab    as the ball, grey, g 0.6                                as the ball
  skin    as the ball, IOR 1.4 (mean free paths 0.2, 0.12, 0.08)  dielectric int_ior 1.4, interior
                                                                  as the ball's
The fog variant adds rt's `--fog-density 0.15 --fog-anisotropy 0.3` (albedo 1); in Mitsuba a
homogeneous medium that the sensor sits in and that is the exterior of every shape.

Needs: `pip install mitsuba` (llvm_ad_rgb: `apt-get install libllvm19`) and a release rt-cli.

Usage: bench/mitsuba-media.py [--spp 4096] [--rt-spp 1024] [--out tests/data/mitsuba-media]
(Mitsuba renders the scene without fog at twice --spp.)
Writes OUT/{scene.gltf,reference.exr,reference-fog.exr} and prints the comparison.
"""

import argparse
import base64
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mitsuba_images import compare

ROOT = Path(__file__).resolve().parent.parent
CLI = ROOT / "target" / "release" / "rt-cli"
WIDTH, HEIGHT, DEPTH = 160, 120, 64
CAMERA = {"from": [0.0, 1.5, 4.2], "to": [0.0, 0.45, 0.0], "vfov": 35.0}
FOG = {"density": 0.15, "anisotropy": 0.3}
# (attenuation colour, attenuation distance, multiscatter colour, anisotropy)
BALL = ([0.05, 0.1, 0.2], 0.5, [0.9, 0.7, 0.5], 0.3)
SLAB = ([0.22, 0.22, 0.22], 1.0, [0.8, 0.8, 0.8], 0.6)
# Subsurface scattering: mean free paths (0.2, 0.12, 0.08), i.e. attenuation colour e^(-0.1/r) at
# distance 0.1, behind a smooth boundary of index 1.4 (rt's `subsurface` maps onto exactly this).
SKIN = ([math.exp(-0.1 / r) for r in (0.2, 0.12, 0.08)], 0.1, [0.9, 0.6, 0.45], 0.0)
SKIN_IOR = 1.4


MEDIA = {"ball": BALL, "slab": SLAB, "skin": SKIN}


def single_scatter_albedo(c):
    """rt_core::math::medium::single_scatter_albedo (Chiang et al. 2016)."""
    if c <= 0:
        return 0.0
    if c >= 1:
        return 1.0
    s = 4.09712 + 4.20863 * c - math.sqrt(9.59217 + 41.6808 * c + 17.7126 * c * c)
    return min(max(1 - s * s, 0.0), 1.0)


def sphere(cx, cy, cz, r, rings=32, segments=64):
    verts, faces = [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments + 1):
            ph = 2 * math.pi * j / segments
            verts.append((cx + r * math.sin(th) * math.cos(ph), cy + r * math.cos(th),
                          cz + r * math.sin(th) * math.sin(ph)))
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j
            b = a + segments + 1
            faces += [(a, a + 1, b + 1), (a, b + 1, b)]
    return verts, faces


def box(lo, hi):
    """Outward-facing (counter-clockwise seen from outside)."""
    verts, faces = [], []
    for axis in range(3):
        for side in (0, 1):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(verts)
            for a, b in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis] = hi[axis] if side else lo[axis]
                p[u] = hi[u] if a else lo[u]
                p[v] = hi[v] if b else lo[v]
                verts.append(tuple(p))
            quad = [(base, base + 1, base + 2), (base, base + 2, base + 3)]
            faces += quad if side else [(a, c, b) for a, b, c in quad]
    return verts, faces


def objects():
    """(name, vertices, counter-clockwise faces)."""
    yield "floor", [(-3, 0, -3), (-3, 0, 3), (3, 0, 3), (3, 0, -3)], [(0, 1, 2), (0, 2, 3)]
    # Facing down (counter-clockwise seen from below).
    yield "light", [(-1, 2.4, -1), (1, 2.4, -1), (1, 2.4, 1), (-1, 2.4, 1)], \
        [(0, 1, 2), (0, 2, 3)]
    v, f = sphere(-0.75, 0.57, 0.0, 0.55)
    yield "ball", v, f
    v, f = box((0.1, 0.02, -0.6), (1.5, 0.52, 0.6))
    yield "slab", v, f
    v, f = sphere(0.15, 0.32, 1.0, 0.3)
    yield "skin", v, f


def gltf_material(name):
    no_specular = {"KHR_materials_specular": {"specularFactor": 0.0}}
    if name == "floor":
        return {"name": name, "extensions": no_specular,
                "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1],
                                         "metallicFactor": 0, "roughnessFactor": 1}}
    if name == "light":
        return {"name": name, "emissiveFactor": [1, 1, 1],
                "extensions": {**no_specular, "KHR_materials_emissive_strength":
                               {"emissiveStrength": 2.0}},
                "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1],
                                         "metallicFactor": 0, "roughnessFactor": 1}}
    colour, distance, multiscatter, g = MEDIA[name]
    return {"name": name, "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1],
                                                   "metallicFactor": 0, "roughnessFactor": 0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                           "KHR_materials_ior": {"ior": SKIN_IOR if name == "skin" else 1.0},
                           "KHR_materials_volume": {"thicknessFactor": 1.0,
                                                    "attenuationColor": colour,
                                                    "attenuationDistance": distance},
                           "KHR_materials_volume_scatter": {"multiscatterColor": multiscatter,
                                                            "scatterAnisotropy": g}}}


def write_gltf(path):
    blob, accessors, views, meshes, nodes, materials = b"", [], [], [], [], []
    for i, (name, verts, faces) in enumerate(objects()):
        pos = b"".join(struct.pack("<3f", *v) for v in verts)
        idx = b"".join(struct.pack("<3I", *f) for f in faces)
        for data, target in ((pos, 34962), (idx, 34963)):
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data),
                          "target": target})
            blob += data
        lo = [min(v[k] for v in verts) for k in range(3)]
        hi = [max(v[k] for v in verts) for k in range(3)]
        accessors.append({"bufferView": len(views) - 2, "componentType": 5126,
                          "count": len(verts), "type": "VEC3", "min": lo, "max": hi})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5125,
                          "count": 3 * len(faces), "type": "SCALAR"})
        materials.append(gltf_material(name))
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                     "indices": len(accessors) - 1,
                                                     "material": i}]})
        nodes.append({"name": name, "mesh": i})
    doc = {
        "asset": {"version": "2.0", "generator": "rt bench/mitsuba-media.py"},
        "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength",
                           "KHR_materials_transmission", "KHR_materials_ior",
                           "KHR_materials_volume", "KHR_materials_volume_scatter"],
        "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
        "meshes": meshes, "materials": materials, "accessors": accessors, "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64,"
                            + base64.b64encode(blob).decode()}],
    }
    path.write_text(json.dumps(doc, indent=1) + "\n")


def medium(params):
    colour, distance, multiscatter, g = params
    sigma_t = [-math.log(c) / distance for c in colour]
    # Mitsuba reads an RGB as a reflectance in [0, 1]: the largest channel goes into `scale`.
    scale = max(sigma_t)
    return {"type": "homogeneous",
            "sigma_t": {"type": "rgb", "value": [s / scale for s in sigma_t]},
            "albedo": {"type": "rgb", "value": [single_scatter_albedo(c) for c in multiscatter]},
            "phase": {"type": "hg", "g": g}, "scale": scale}


def mitsuba_scene(mi, tmp, spp, fog):
    fog_medium = None
    if fog:
        fog_medium = {"type": "homogeneous", "sigma_t": FOG["density"], "albedo": 1.0,
                      "phase": {"type": "hg", "g": FOG["anisotropy"]}}
    scene = {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": DEPTH},
        "sensor": {
            "type": "perspective", "fov": CAMERA["vfov"], "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=CAMERA["from"], target=CAMERA["to"],
                                                      up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": WIDTH, "height": HEIGHT,
                     "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    if fog:
        scene["fog"] = fog_medium
        scene["sensor"]["medium"] = {"type": "ref", "id": "fog"}
    for i, (name, verts, faces) in enumerate(objects()):
        path = Path(tmp) / f"{i}.obj"
        path.write_text("".join("v {} {} {}\n".format(*v) for v in verts)
                        + "".join("f {} {} {}\n".format(*(j + 1 for j in f)) for f in faces))
        shape = {"type": "obj", "filename": str(path), "face_normals": True}
        if name == "floor":
            shape["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5] * 3}}
        elif name == "light":
            shape["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0] * 3}}
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": [2.0] * 3}}
        elif name == "skin":
            shape["bsdf"] = {"type": "dielectric", "int_ior": SKIN_IOR, "ext_ior": 1.0}
            shape["interior"] = medium(SKIN)
        else:
            shape["bsdf"] = {"type": "null"}
            shape["interior"] = medium(MEDIA[name])
        if fog:
            shape["exterior"] = {"type": "ref", "id": "fog"}
        scene[f"shape_{i}"] = shape
    return scene


def rt_render(out, spp, target, fog):
    started = time.perf_counter()
    flags = ["--fog-density", str(FOG["density"]), "--fog-anisotropy",
             str(FOG["anisotropy"])] if fog else []
    subprocess.run(
        [str(CLI), "render", str(out / "scene.gltf"), "--device", "cpu",
         "--camera-from", ",".join(map(str, CAMERA["from"])),
         "--camera-to", ",".join(map(str, CAMERA["to"])), "--vfov", str(CAMERA["vfov"]),
         "--width", str(WIDTH), "--height", str(HEIGHT), "--max-depth", str(DEPTH),
         "--spp", str(spp), "--ambient", "0,0,0", "-o", str(target)] + flags,
        check=True, capture_output=True,
    )
    return time.perf_counter() - started


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=4096)
    parser.add_argument("--rt-spp", type=int, default=1024)
    parser.add_argument("--out", default=str(ROOT / "tests" / "data" / "mitsuba-media"))
    args = parser.parse_args()
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_gltf(out / "scene.gltf")
    for fog, name in ((False, "reference.exr"), (True, "reference-fog.exr")):
        # Twice the samples without fog, where they are cheap and the dense ball's noise is not.
        spp = args.spp if fog else 2 * args.spp
        with tempfile.TemporaryDirectory() as tmp:
            started = time.perf_counter()
            scene = mi.load_dict(mitsuba_scene(mi, tmp, spp, fog))
            image = mi.render(scene, spp=spp, seed=7)
            mi.Bitmap(image).write(str(out / name))
            t_mitsuba = time.perf_counter() - started
            rt_out = Path(tmp) / "rt.exr"
            t_rt = rt_render(out, args.rt_spp, rt_out, fog)
            means, blocks, bad = compare(mi, rt_out, out / name, WIDTH, HEIGHT)
        print(f"{'with' if fog else 'without'} fog: Mitsuba 3 {mi.__version__} llvm_ad_rgb, "
              f"{spp} spp: {t_mitsuba:.1f} s; rt (CPU backend) {args.rt_spp} spp: "
              f"{t_rt:.1f} s (with start-up)")
        for ch, (a, b, d) in zip("RGB", means):
            print(f"  mean {ch}: rt {a:.5f} Mitsuba {b:.5f} ({100 * d:+.2f}%)")
        print(f"  32-px blocks off by more than 5%: {bad} of {blocks}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
