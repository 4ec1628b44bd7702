#!/usr/bin/env python3
"""rt's clear coat, sheen, specular, thin film and anisotropy (KHR_materials_clearcoat, _sheen,
_specular, _iridescence, _anisotropy) against Blender Cycles, per object: builds a row of spheres in
Blender's `bpy` with Principled BSDFs (a plain red plastic as the control; the same plastic under a
clear coat; a specular-tinted, half-strength dielectric; a velvet with a sheen; a steel with a
coat; a dark dielectric under a soap film; a brushed steel, anisotropic along its UV tangents),
exports them with Blender's glTF exporter (which writes the coat, sheen, specular and anisotropy;
`patch` adds the film as KHR_materials_iridescence, which the exporter does not write, and maps
the brushed steel's Anisotropic onto glTF's parameters, see below), renders Cycles' reference on
the CPU and rt from the .glb, and compares each object's pixels (Cycles' object-index pass marks
them) and the image.

Matched on purpose:
  - light: a uniform grey world in Cycles and the same ambient radiance in rt (`--ambient`; glTF has
    no world), plus a sun (no angle: a delta light in both);
  - Cycles' film: a 1-pixel box filter, no clamping or denoising, bounces = rt's max depth − 1;
  - what Cycles models differently from the glTF extensions, reported rather than hidden (see
    docs/quality.md): its sheen is Zeltner's microfibre model, not Charlie; its coat is a layer
    with its own tint and refraction of the base's light; the exporter maps Specular IOR Level and
    Tint onto specularFactor and specularColorFactor, and Cycles keeps F90 = 1 where glTF scales it;
  - anisotropy: Cycles widens the GGX lobe as α_x = α/a, α_y = α·a with a = √(1 − 0.9·Anisotropic),
    glTF as α_t = mix(α, 1, s²), α_b = α, and the exporter copies Anisotropic into
    anisotropyStrength; `patch` sets the brushed steel's roughness and strength to the glTF values
    whose widths are Cycles' (r = √α_y, s = √((α_x − α_y)/(1 − α_y))), so both render one lobe.
    Its tangents are the UV map's (MikkTSpace) in both: a Tangent node in Cycles.

`--set glass` builds another row instead: smooth and rough glass (roughness 0.2, 0.4, 0.7), a
tinted rough glass, rough water (IOR 1.33) and a rough dense glass (IOR 1.8), all Principled
Transmission. Solid spheres: `patch` gives every transmissive material KHR_materials_volume (glTF
reads transmission without it as a thin wall; Cycles refracts into the solid). Not compared:
dispersion (Blender 5.2's Principled and Glass BSDFs have no Dispersion input; its exporter takes
KHR_materials_dispersion from the glTF Material Output node, which Cycles does not render).

Needs: Python 3.13 with `pip install bpy==5.2.3 OpenEXR`, and a release rt-cli.

Usage: python3.13 bench/cycles-layers.py [--set layers|glass] [--spp 1024] [--rt-spp 1024]
       [--out DIR]
Writes OUT/{scene.glb,reference.exr} (OUT is tests/data/cycles-SET by default;
`tests/cycles_layers.rs` reads them) and prints the comparison.
"""

import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from cycles_settings import (
    add_camera,
    arguments,
    export_glb,
    read_channels,
    render_with_object_index,
)

ROOT = Path(__file__).resolve().parent.parent
CLI = ROOT / "target" / "release" / "rt-cli"
WIDTH, HEIGHT, DEPTH = 448, 128, 8
AMBIENT = 0.5
# The thin film: Blender's exporter does not write Principled's Thin Film as
# KHR_materials_iridescence, so `patch` adds the same film to the exported file.
FILM_NM, FILM_IOR = 400.0, 1.33
# The brushed steel's Principled roughness and Anisotropic.
BRUSHED_ROUGHNESS, BRUSHED_ANISOTROPIC = 0.5, 0.8

# name, x, Principled inputs
SPHERES = [
    ("plastic", -3.6, {"Base Color": (0.7, 0.1, 0.1, 1), "Roughness": 0.5}),
    ("coated", -2.4, {"Base Color": (0.7, 0.1, 0.1, 1), "Roughness": 0.5,
                      "Coat Weight": 1.0, "Coat Roughness": 0.05}),
    ("specular", -1.2, {"Base Color": (0.1, 0.3, 0.1, 1), "Roughness": 0.3,
                        "Specular IOR Level": 0.35, "Specular Tint": (1.0, 0.6, 0.3, 1)}),
    ("velvet", 0.0, {"Base Color": (0.1, 0.1, 0.4, 1), "Roughness": 0.8,
                     "Sheen Weight": 1.0, "Sheen Tint": (1.0, 0.8, 0.6, 1), "Sheen Roughness": 0.5}),
    ("coated steel", 1.2, {"Base Color": (0.8, 0.8, 0.8, 1), "Metallic": 1.0, "Roughness": 0.5,
                           "Coat Weight": 0.8, "Coat Roughness": 0.1}),
    ("soap film", 2.4, {"Base Color": (0.05, 0.05, 0.05, 1), "Roughness": 0.2,
                        "Thin Film Thickness": FILM_NM, "Thin Film IOR": FILM_IOR}),
    ("brushed steel", 3.6, {"Base Color": (0.8, 0.8, 0.8, 1), "Metallic": 1.0,
                            "Roughness": BRUSHED_ROUGHNESS, "Anisotropic": BRUSHED_ANISOTROPIC}),
]


def glass(roughness, color=(1, 1, 1, 1), ior=1.5):
    return {"Base Color": color, "Transmission Weight": 1.0, "Roughness": roughness, "IOR": ior}


GLASS = [
    ("clear glass", -3.6, glass(0.0)),
    ("rough glass 0.2", -2.4, glass(0.2)),
    ("rough glass 0.4", -1.2, glass(0.4)),
    ("rough glass 0.7", 0.0, glass(0.7)),
    ("tinted rough glass", 1.2, glass(0.3, color=(0.9, 0.5, 0.3, 1), ior=1.45)),
    ("rough water", 2.4, glass(0.15, ior=1.33)),
    ("rough dense glass", 3.6, glass(0.3, ior=1.8)),
]
SETS = {"layers": SPHERES, "glass": GLASS}


def build(bpy, spheres):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, 0))
    floor = bpy.context.object
    floor.name = "floor"
    m = bpy.data.materials.new("grey")
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1)
    bsdf.inputs["Roughness"].default_value = 1.0
    floor.data.materials.append(m)
    floor.pass_index = 1
    for k, (name, x, inputs) in enumerate(spheres):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(x, 0, 0.5), segments=64,
                                             ring_count=32)
        bpy.ops.object.shade_smooth()
        obj = bpy.context.object
        obj.name = name
        obj.pass_index = k + 2
        m = bpy.data.materials.new(name)
        m.use_nodes = True
        bsdf = m.node_tree.nodes["Principled BSDF"]
        for key, value in inputs.items():
            bsdf.inputs[key].default_value = value
        if "Anisotropic" in inputs:
            # Along the UV map's tangents, as glTF's anisotropy (rt's MikkTSpace tangents).
            tangent = m.node_tree.nodes.new("ShaderNodeTangent")
            tangent.direction_type = "UV_MAP"
            m.node_tree.links.new(tangent.outputs["Tangent"], bsdf.inputs["Tangent"])
        obj.data.materials.append(m)
    bpy.ops.object.light_add(type="SUN", rotation=(math.radians(40), 0, math.radians(-30)))
    sun = bpy.context.object.data
    sun.energy = 2.0
    sun.angle = 0.0
    add_camera(bpy, scene, (0.0, -7.0, 1.6), (0.0, 7.0, -1.1), 20)
    world = bpy.data.worlds.new("grey")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (AMBIENT,) * 3 + (1,)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    return scene


def gltf_anisotropy(roughness, anisotropic):
    """The glTF roughness and anisotropyStrength whose GGX widths are Cycles' for a Principled
    roughness and Anisotropic (see the module doc)."""
    alpha = roughness * roughness
    aspect = math.sqrt(1.0 - 0.9 * anisotropic)
    alpha_x, alpha_y = alpha / aspect, alpha * aspect
    return math.sqrt(alpha_y), math.sqrt((alpha_x - alpha_y) / (1.0 - alpha_y))


def patch(glb):
    """Writes KHR_materials_iridescence (the film Blender's Principled BSDF has) into the .glb's
    "soap film" material and Cycles' anisotropic widths into the "brushed steel", and makes every
    transmissive material a solid (KHR_materials_volume); in place."""
    import json
    import struct

    data = glb.read_bytes()
    length = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + length])
    rest = data[20 + length:]
    for m in doc["materials"]:
        if m["name"] == "soap film":
            m.setdefault("extensions", {})["KHR_materials_iridescence"] = {
                "iridescenceFactor": 1.0, "iridescenceIor": FILM_IOR,
                "iridescenceThicknessMaximum": FILM_NM}
        if m["name"] == "brushed steel":
            roughness, strength = gltf_anisotropy(BRUSHED_ROUGHNESS, BRUSHED_ANISOTROPIC)
            m["pbrMetallicRoughness"]["roughnessFactor"] = roughness
            m["extensions"]["KHR_materials_anisotropy"]["anisotropyStrength"] = strength
        extensions = m.get("extensions", {})
        if "KHR_materials_transmission" in extensions:
            extensions.setdefault("KHR_materials_volume", {"thicknessFactor": 1.0})
    used = doc.setdefault("extensionsUsed", [])
    for name in ("KHR_materials_iridescence", "KHR_materials_volume"):
        if name not in used and any(name in m.get("extensions", {}) for m in doc["materials"]):
            used.append(name)
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    chunk = struct.pack("<I", len(text)) + b"JSON" + text
    glb.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(chunk) + len(rest)) + chunk + rest)


def rgb_of(channels):
    import numpy

    for prefix in ("", "ViewLayer.Combined."):
        if all(prefix + c in channels for c in "RGB"):
            return numpy.stack([channels[prefix + c] for c in "RGB"], axis=-1)
    raise SystemExit(f"no RGB channels among {sorted(channels)}")


def main():
    args = arguments(__doc__, 1024, lambda name: ROOT / "tests" / "data" / f"cycles-{name}",
                     list(SETS))
    import bpy
    import numpy

    spheres = SETS[args.set]
    out = Path(args.out)
    scene = build(bpy, spheres)
    export_glb(bpy, out / "scene.glb")
    patch(out / "scene.glb")
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        render_with_object_index(bpy, scene, args.spp, DEPTH, Path(tmp) / "cycles.exr")
        cycles = read_channels(Path(tmp) / "cycles.exr")
    t_cycles = time.perf_counter() - started
    index = next(v for k, v in cycles.items() if "Index" in k)
    theirs = rgb_of(cycles)
    # The reference the test reads: RGB alone, one layer (`image` reads no multilayer files).
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"RGB": theirs.astype("float32")}).write(str(out / "reference.exr"))
    with tempfile.TemporaryDirectory() as tmp:
        rt_out = Path(tmp) / "rt.exr"
        started = time.perf_counter()
        run = subprocess.run([str(CLI), "render", str(out / "scene.glb"), "--width", str(WIDTH),
                              "--height", str(HEIGHT), "--max-depth", str(DEPTH), "--spp",
                              str(args.rt_spp), "--environment", "none", "--ambient",
                              f"{AMBIENT},{AMBIENT},{AMBIENT}", "--device", "auto", "-o",
                              str(rt_out), "-v"],
                             capture_output=True, text=True)
        if run.returncode != 0:
            raise SystemExit(run.stderr)
        warnings = [l for l in run.stderr.splitlines() if "WARN" in l or "warn" in l]
        t_rt = time.perf_counter() - started
        ours = rgb_of(read_channels(rt_out))
    print(f"Blender {bpy.app.version_string} Cycles CPU, {args.spp} spp: {t_cycles:.1f} s; "
          f"rt {args.rt_spp} spp: {t_rt:.1f} s")
    for w in warnings:
        print("rt:", w)
    for ch, name in enumerate("RGB"):
        a, b = ours[..., ch].mean(), theirs[..., ch].mean()
        print(f"image {name}: rt {a:.5f} Cycles {b:.5f} ({100 * (a / b - 1):+.2f}%)")
    print("| object (pixels) | rt R/G/B | Cycles R/G/B | rt / Cycles − 1 |")
    print("| --- | --- | --- | --- |")
    for k, name in enumerate(["floor"] + [s[0] for s in spheres]):
        mask = numpy.abs(index - (k + 1)) < 0.5
        # Not the silhouettes, where a pixel mixes the object and what lies behind.
        inner = mask.copy()
        for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
            inner &= numpy.roll(mask, (dy, dx), axis=(0, 1))
        a = ours[inner].mean(axis=0)
        b = theirs[inner].mean(axis=0)
        print(f"| {name} ({inner.sum()}) | {a[0]:.4f} / {a[1]:.4f} / {a[2]:.4f} | "
              f"{b[0]:.4f} / {b[1]:.4f} / {b[2]:.4f} | "
              + " / ".join(f"{100 * (x / y - 1):+.1f}%" for x, y in zip(a, b)) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
