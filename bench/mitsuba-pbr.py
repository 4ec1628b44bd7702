#!/usr/bin/env python3
"""rt's PBR materials and environment lighting against Mitsuba 3: writes a small scene (OBJ + MTL,
an environment EXR, a camera), renders Mitsuba's reference of it at high spp, and compares rt's
render: per-channel means and 32-px blocks.

The scene: a grey diffuse floor, a white rough conductor (roughness 0.3), a gold metal (0.35), a
rough glass sphere (0.2, IOR 1.5), a smooth glass sphere, a red plastic sphere in front (0.3,
IOR 1.5), a quad area light and an environment map. Mitsuba plugins and the parameters matched
(α = roughness², GGX, visible-normal sampling):
  floor          rt Lambertian (Kd 0.5)            Mitsuba diffuse, reflectance 0.5
  white metal    rt Pbr metallic 1, roughness 0.3   roughconductor ggx, alpha 0.09, material none
                                                    (F = 1: rt's Schlick with F0 = 1 is 1 too)
  gold           rt Pbr metallic 1, roughness 0.35  principled, base_color gold, metallic 1,
                                                    roughness 0.35 (Schlick with F0 = base colour)
  rough glass    rt Pbr transmission 1, 0.2, 1.5    roughdielectric ggx, alpha 0.04, int_ior 1.5
  smooth glass   rt Dielectric 1.5                  dielectric, int_ior 1.5
  plastic        rt Pbr metallic 0, roughness 0.3,  principled, base_color, metallic 0,
                 IOR 1.5                            roughness 0.3, eta 1.5, no sheen, clearcoat
                                                    or specular tint
  light          Ke 6 (front face)                  area, radiance 6
  environment    --environment env.exr              envmap (same lat-long mapping, y up)
Mitsuba's conductors scatter once; rt adds Turquin's multiple-scattering energy (about 1% at
these roughnesses). rt looks the environment up at the nearest texel, Mitsuba bilinearly; the map
is smooth. Mitsuba has no plugin for glTF's dielectric-over-diffuse layering: `principled`'s
diffuse is Disney's (retro-reflective at grazing angles, not weighted by 1 − F) and
`roughplastic` adds a coating's internal reflections, so the plastic is compared with
`principled`, the nearer of the two, and its own region's difference is reported apart.

Needs: `pip install mitsuba` (llvm_ad_rgb: `apt-get install libllvm19`) and a release rt-cli.

Usage: bench/mitsuba-pbr.py [--spp 4096] [--rt-spp 1024] [--out tests/data/mitsuba-pbr]
Writes OUT/{scene.obj,scene.mtl,env.exr,reference.exr} and prints the comparison.
"""

import argparse
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mitsuba_images import compare

ROOT = Path(__file__).resolve().parent.parent
CLI = ROOT / "target" / "release" / "rt-cli"
WIDTH, HEIGHT, DEPTH = 256, 192, 8
CAMERA = {"from": [0.0, 1.6, 5.2], "to": [0.0, 0.55, 0.0], "vfov": 32.0}
# The plastic sphere in front of the row (centre x, y, z and radius).
PLASTIC = (0.0, 0.3, 1.2, 0.3)

MTL = """newmtl floor
Kd 0.5 0.5 0.5
newmtl white_metal
Kd 1 1 1
Pm 1
Pr 0.3
newmtl gold
Kd 1 0.766 0.336
Pm 1
Pr 0.35
newmtl rough_glass
illum 7
Ni 1.5
Pr 0.2
newmtl smooth_glass
illum 7
Ni 1.5
newmtl plastic
Kd 0.6 0.15 0.1
Pm 0
Pr 0.3
Ni 1.5
newmtl light
Ke 6 6 6
"""


def sphere(cx, cy, cz, r, rings=24, segments=48):
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


def objects():
    """(name, material, vertices, counter-clockwise faces), y up."""
    yield "floor", "floor", [(-3, 0, -3), (-3, 0, 3), (3, 0, 3), (3, 0, -3)], [(0, 1, 2), (0, 2, 3)]
    for k, material in enumerate(["white_metal", "gold", "rough_glass", "smooth_glass"]):
        v, f = sphere(-1.65 + 1.1 * k, 0.5, 0.0, 0.5)
        yield material, material, v, f
    v, f = sphere(*PLASTIC)
    yield "plastic", "plastic", v, f
    # Facing down (counter-clockwise seen from below).
    yield "light", "light", [(-0.6, 2.6, -0.6), (0.6, 2.6, -0.6), (0.6, 2.6, 0.6), (-0.6, 2.6, 0.6)], \
        [(0, 1, 2), (0, 2, 3)]


def write_scene(out):
    lines, base = ["mtllib scene.mtl"], 1
    for name, material, verts, faces in objects():
        lines += [f"o {name}", f"usemtl {material}"]
        lines += ["v {:.6f} {:.6f} {:.6f}".format(*v) for v in verts]
        lines += ["f " + " ".join(str(base + i) for i in f) for f in faces]
        base += len(verts)
    (out / "scene.obj").write_text("\n".join(lines) + "\n")
    (out / "scene.mtl").write_text(MTL)


def environment(mi):
    """A smooth sky: a blue gradient, a warm soft sun and a dark ground, 256 x 128."""
    w, h = 256, 128
    sun = (0.5, 0.6, -0.62)
    n = math.sqrt(sum(c * c for c in sun))
    sun = [c / n for c in sun]
    data = []
    for y in range(h):
        for x in range(w):
            u, v = (x + 0.5) / w, (y + 0.5) / h
            phi, theta = 2 * math.pi * u, math.pi * v
            d = (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))
            c = max(0.0, sum(a * b for a, b in zip(d, sun)))
            glow = 25.0 * math.exp((c - 1.0) * 40.0)
            if d[1] > 0:
                sky = (0.35 + 0.3 * (1 - d[1]), 0.5 + 0.25 * (1 - d[1]), 0.9)
            else:
                sky = (0.12, 0.1, 0.08)
            data += [sky[0] + glow, sky[1] + 0.8 * glow, sky[2] + 0.55 * glow]
    return mi.Bitmap(mi.TensorXf(data, shape=(h, w, 3)))


def mitsuba_scene(mi, out, tmp, spp):
    bsdfs = {
        "floor": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5, 0.5, 0.5]}},
        "white_metal": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.09,
                        "material": "none"},
        "gold": {"type": "principled", "base_color": {"type": "rgb", "value": [1.0, 0.766, 0.336]},
                 "metallic": 1.0, "roughness": 0.35},
        "rough_glass": {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.04,
                        "int_ior": 1.5, "ext_ior": 1.0},
        "smooth_glass": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
        "plastic": {"type": "principled",
                    "base_color": {"type": "rgb", "value": [0.6, 0.15, 0.1]},
                    "metallic": 0.0, "roughness": 0.3, "eta": 1.5, "spec_tint": 0.0,
                    "sheen": 0.0, "clearcoat": 0.0, "spec_trans": 0.0},
        "light": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}},
    }
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": DEPTH},
        "sensor": {
            "type": "perspective", "fov": CAMERA["vfov"], "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=CAMERA["from"], target=CAMERA["to"],
                                                      up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": WIDTH, "height": HEIGHT,
                     "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "env": {"type": "envmap", "filename": str(out / "env.exr")},
    }
    for i, (name, material, verts, faces) in enumerate(objects()):
        path = Path(tmp) / f"{i}.obj"
        path.write_text("".join("v {} {} {}\n".format(*v) for v in verts)
                        + "".join("f {} {} {}\n".format(*(j + 1 for j in f)) for f in faces))
        shape = {"type": "obj", "filename": str(path), "face_normals": True, "bsdf": bsdfs[material]}
        if material == "light":
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": [6.0, 6.0, 6.0]}}
        scene[f"shape_{i}"] = shape
    return scene


def rt_render(out, spp, target):
    started = time.perf_counter()
    subprocess.run(
        [str(CLI), "render", str(out / "scene.obj"), "--environment", str(out / "env.exr"),
         "--camera-from", ",".join(map(str, CAMERA["from"])),
         "--camera-to", ",".join(map(str, CAMERA["to"])), "--vfov", str(CAMERA["vfov"]),
         "--width", str(WIDTH), "--height", str(HEIGHT), "--max-depth", str(DEPTH),
         "--spp", str(spp), "-o", str(target)],
        check=True, capture_output=True,
    )
    return time.perf_counter() - started


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=4096)
    parser.add_argument("--rt-spp", type=int, default=1024)
    parser.add_argument("--out", default=str(ROOT / "tests" / "data" / "mitsuba-pbr"))
    args = parser.parse_args()
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_scene(out)
    environment(mi).write(str(out / "env.exr"))
    with tempfile.TemporaryDirectory() as tmp:
        started = time.perf_counter()
        scene = mi.load_dict(mitsuba_scene(mi, out, tmp, args.spp))
        image = mi.render(scene, spp=args.spp, seed=7)
        mi.Bitmap(image).write(str(out / "reference.exr"))
        t_mitsuba = time.perf_counter() - started
        rt_out = Path(tmp) / "rt.exr"
        t_rt = rt_render(out, args.rt_spp, rt_out)
        means, blocks, bad = compare(mi, rt_out, out / "reference.exr", WIDTH, HEIGHT)
    print(f"Mitsuba 3 {mi.__version__} llvm_ad_rgb, {args.spp} spp: {t_mitsuba:.1f} s")
    print(f"rt {args.rt_spp} spp: {t_rt:.1f} s (with start-up)")
    for ch, (a, b, d) in zip("RGB", means):
        print(f"mean {ch}: rt {a:.5f} Mitsuba {b:.5f} ({100 * d:+.2f}%)")
    print(f"32-px blocks off by more than 5%: {bad} of {blocks}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
