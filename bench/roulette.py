#!/usr/bin/env python3
"""Russian roulette's efficiency over a set of scenes (docs/quality.md, "Russian roulette").

For each scene: a reference without roulette at --ref-spp, then renders at --spp with rt's
roulette and without it, over several seeds; prints the render time, relMSE against the
reference and their product (lower is better: the time to a given error). Run from the repo
root after `cargo build --release -p rt-cli`; one render at a time, nothing else running.

    python3 bench/roulette.py [--device cpu] [--size 128] [--spp 256] [--ref-spp 4096]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CLI = os.path.join(ROOT, "target", "release", "rt-cli")


def scenes():
    caustics = os.path.join(ROOT, "bench", "scenes", "glass-caustics")
    if not os.path.exists(os.path.join(caustics, "glass-caustics.obj")):
        subprocess.run([sys.executable, "make.py"], cwd=caustics, check=True)
    lights = os.path.join(ROOT, "bench", "scenes", "many-lights")
    return {
        "cornell": [],
        "glass-caustics": [os.path.join(caustics, "glass-caustics.obj"),
                           "--camera", os.path.join(caustics, "camera.json")],
        "cycles-glass": [os.path.join(ROOT, "tests", "data", "cycles-glass", "scene.glb")],
        "many-lights": [os.path.join(lights, "room.obj"),
                        "--camera", os.path.join(lights, "camera.json")],
        "media": [os.path.join(ROOT, "tests", "data", "mitsuba-media", "scene.gltf")],
        "spot (textured)": [os.path.join(ROOT, "assets", "spot", "spot_triangulated_textured.obj")],
    }


def render(args, common, spp, seed, out, extra=()):
    r = subprocess.run([CLI, "render", *args, *common, "--spp", str(spp), "--seed", str(seed),
                        "-o", out, *extra], capture_output=True, text=True)
    if r.returncode:
        sys.exit(r.stderr)
    m = re.search(r"render time:\s+([\d.]+)(ms|s)", r.stdout + r.stderr)
    return float(m.group(1)) / (1000.0 if m.group(2) == "ms" else 1.0)


def rel_mse(image, reference):
    r = subprocess.run([CLI, "compare", image, reference], capture_output=True, text=True)
    return float(re.search(r"relMSE:\s*([\d.eE+-]+)", r.stdout + r.stderr).group(1))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--device", default="cpu")
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--seeds", default="1,2,3")
    a = p.parse_args()
    common = ["--width", str(a.size), "--height", str(a.size), "--device", a.device]
    seeds = [int(s) for s in a.seeds.split(",")]
    tmp = tempfile.mkdtemp(prefix="rt-roulette-")
    print(f"{'scene':16s} {'rule':12s} {'time s':>8s} {'relMSE':>10s} {'time*relMSE':>12s}")
    for name, args in scenes().items():
        ref = os.path.join(tmp, "ref.exr")
        render(args, common, a.ref_spp, 99991, ref, ["--no-roulette"])
        rows = {}
        for rule, extra in [("roulette", []), ("no roulette", ["--no-roulette"])]:
            t = e = 0.0
            for seed in seeds:
                out = os.path.join(tmp, "out.exr")
                t += render(args, common, a.spp, seed, out, extra) / len(seeds)
                e += rel_mse(out, ref) / len(seeds)
            rows[rule] = t * e
            print(f"{name:16s} {rule:12s} {t:8.3f} {e:10.4e} {t * e:12.4e}", flush=True)
        print(f"{name:16s} efficiency gain of roulette: {rows['no roulette'] / rows['roulette']:.2f}x")


if __name__ == "__main__":
    main()
