#!/usr/bin/env python3
"""rt against Mitsuba 3 on the Cornell box, on the same machine: both render assets/cornell at
512x512, max depth 8, 256 spp; each image's relMSE is measured against a high-spp reference, and
the equal-error time ratio (t_rt * relMSE_rt) / (t_mitsuba * relMSE_mitsuba) is printed: below 1,
rt reaches a given error sooner (for unbiased estimators error * time is constant).

Needs: `pip install mitsuba` (its llvm_ad_rgb variant runs on the CPU through LLVM:
`apt-get install libllvm19`; LLVM 15, which Mesa installs, crashes compiling Dr.Jit's AVX-512 kernels
here, and LLVM 14 is too old; DRJIT_LIBLLVM_PATH overrides the library), and a release rt-cli
(`cargo build --release -p rt-cli`).

Usage: bench/mitsuba-vs-rt.py REFERENCE.exr [--spp 256] [--size 512] [--sampler independent|sobol]
       [--device gpu|cpu] [--cli PATH] [--cycles PYTHON3.13]
(rt's own default sampler, Sobol, unless --sampler is given; Mitsuba keeps its independent one;
--device cpu renders rt with its native CPU backend rather than through wgpu; --cli runs another
rt-cli binary, to compare two builds side by side; --cycles renders the same box with Blender Cycles
on the CPU through that Python (3.13 with `pip install bpy==5.2.3`; `cycles_cornell.py`) and adds
its row and ratio)
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from cornell_scene import parse_cornell

ROOT = Path(__file__).resolve().parent.parent
CLI = ROOT / "target" / "release" / "rt-cli"


def mitsuba_scene(mi, folder, size, spp, tmp):
    vertices, objects, mtl = parse_cornell(folder)
    camera = json.loads((folder / "cornell.json").read_text())
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 8},
        "sensor": {
            "type": "perspective",
            "fov": camera["vfov"],
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=camera["from"], target=camera["to"], up=camera["up"]
            ),
            "film": {
                "type": "hdrfilm",
                "width": size,
                "height": size,
                "rfilter": {"type": "box"},
            },
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    for i, obj in enumerate(objects):
        used = sorted({v for f in obj["faces"] for v in f})
        remap = {v: k + 1 for k, v in enumerate(used)}
        path = Path(tmp) / f"{i}.obj"
        with open(path, "w") as f:
            for v in used:
                f.write("v {} {} {}\n".format(*vertices[v]))
            for face in obj["faces"]:
                f.write("f " + " ".join(str(remap[v]) for v in face) + "\n")
        m = mtl.get(obj["material"], {})
        shape = {
            "type": "obj",
            "filename": str(path),
            "face_normals": True,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": m.get("Kd", [0, 0, 0])}},
        }
        if any(m.get("Ke", [0, 0, 0])):
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": m["Ke"]}}
        scene[f"shape_{i}"] = shape
    return scene


def rel_mse(image, reference):
    out = subprocess.run(
        [str(CLI), "compare", str(image), str(reference)], capture_output=True, text=True, check=True
    ).stdout
    return float(re.search(r"relMSE:\s+(\S+)", out).group(1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("reference")
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--sampler", default=None)
    parser.add_argument("--device", default="gpu", choices=["gpu", "cpu"])
    parser.add_argument("--cli", type=Path, default=CLI)
    parser.add_argument("--cycles", metavar="PYTHON3.13", default=None)
    args = parser.parse_args()
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    folder = ROOT / "assets" / "cornell"
    with tempfile.TemporaryDirectory() as tmp:
        scene = mi.load_dict(mitsuba_scene(mi, folder, args.size, args.spp, tmp))
        # Dr.Jit records lazily and launches kernels asynchronously: time a second render (kernels
        # compiled and cached by the first) up to the end of its evaluation.
        for _ in range(2):
            started = time.perf_counter()
            image = mi.render(scene, spp=args.spp, seed=1)
            dr.eval(image)
            dr.sync_thread()
            t_mitsuba = time.perf_counter() - started
        mitsuba_out = Path(tmp) / "mitsuba.exr"
        mi.Bitmap(image).write(str(mitsuba_out))
        rt_out = Path(tmp) / "rt.exr"
        started = time.perf_counter()
        log = subprocess.run(
            [str(args.cli), "render", "--width", str(args.size), "--height", str(args.size),
             "--spp", str(args.spp), "--max-depth", "8", "-o", str(rt_out),
             "--device", args.device]
            + (["--sampler", args.sampler] if args.sampler else []),
            capture_output=True, text=True, check=True,
        ).stderr
        t_rt_wall = time.perf_counter() - started
        t_rt = float(re.search(r"render time:\s+([\d.]+)(ms|s)", log).group(1))
        if re.search(r"render time:\s+[\d.]+ms", log):
            t_rt /= 1000.0
        e_mitsuba = rel_mse(mitsuba_out, args.reference)
        e_rt = rel_mse(rt_out, args.reference)
        cycles = None
        if args.cycles:
            cycles_out = Path(tmp) / "cycles.exr"
            log_cycles = subprocess.run(
                [args.cycles, str(ROOT / "bench" / "cycles_cornell.py"), str(cycles_out),
                 "--size", str(args.size), "--spp", str(args.spp)],
                capture_output=True, text=True, check=True,
            ).stdout
            t_cycles = float(re.search(r"cycles render time:\s+([\d.]+)", log_cycles).group(1))
            cycles = (t_cycles, rel_mse(cycles_out, args.reference))
    ratio = (t_rt * e_rt) / (t_mitsuba * e_mitsuba)
    adapter = re.search(r"(?:adapter|device):\s+(.*)", log).group(1)
    print(f"machine: {os.cpu_count()} CPUs; rt adapter: {adapter}")
    print(f"{'':10} {'time (s)':>10} {'relMSE':>12}")
    print(f"{'Mitsuba 3':10} {t_mitsuba:>10.2f} {e_mitsuba:>12.4e}   (llvm_ad_rgb, path, independent)")
    sampler = args.sampler or "default sampler"
    print(f"{'rt':10} {t_rt:>10.2f} {e_rt:>12.4e}   ({sampler}; render time; {t_rt_wall:.2f} s with start-up, BVH, save)")
    if cycles:
        t_cycles, e_cycles = cycles
        print(f"{'Cycles':10} {t_cycles:>10.2f} {e_cycles:>12.4e}   (Blender 5.2 CPU, path, no adaptive sampling)")
    print(f"equal-error time ratio (t_rt relMSE_rt) / (t_mitsuba relMSE_mitsuba): {ratio:.3f}")
    if cycles:
        print(f"equal-error time ratio (t_rt relMSE_rt) / (t_cycles relMSE_cycles): "
              f"{(t_rt * e_rt) / (t_cycles * e_cycles):.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
