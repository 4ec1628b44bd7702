"""rt's projections against Cycles' cameras on the Cornell box (assets/cornell), per region.

Renders the box with Cycles (CPU) through an orthographic, an equirectangular panorama or an
equidistant fisheye camera placed by an rt camera file, renders the same with `rt-cli`, and prints
both images' means over a grid of regions and their ratios (rt / Cycles): a wrong mapping shows as
regions off by far more than the noise. Both are read as linear EXR (OpenEXR, numpy).

Needs Python 3.13 with `pip install bpy==5.2.3` and a release rt-cli.

Usage: python3.13 bench/cycles_cameras.py {orthographic,panorama,fisheye} [--rt target/release/rt-cli]
       [--spp 256] [--grid 4]
"""

import argparse
import json
import math
import subprocess
import tempfile
from pathlib import Path

import bpy

from cycles_cornell import build
from cycles_settings import look_at

ROOT = Path(__file__).resolve().parent.parent
OUTSIDE = {"from": [278, 273, -800], "to": [278, 273, -799], "up": [0, 1, 0], "vfov": 39.3077}
INSIDE = {"from": [278, 273, 280], "to": [278, 273, 560], "up": [0, 1, 0], "vfov": 39.3077}
CASES = {
    # (camera, width, height, rt flags): the orthographic height rt takes by default (the
    # perspective view's height at the box's centre), set explicitly for both.
    "orthographic": (OUTSIDE, 128, 128, ["--projection", "orthographic", "--ortho-height", "771.3"]),
    "panorama": (INSIDE, 256, 128, ["--projection", "panorama"]),
    "fisheye": (INSIDE, 128, 128, ["--projection", "fisheye", "--fisheye-angle", "180"]),
}


def cycles_camera(scene, projection, camera):
    cam = scene.camera.data
    scene.camera.matrix_world = look_at(camera)
    if projection == "orthographic":
        cam.type = "ORTHO"
        cam.sensor_fit = "VERTICAL"
        cam.ortho_scale = 771.3
    else:
        cam.type = "PANO"
        if projection == "panorama":
            cam.panorama_type = "EQUIRECTANGULAR"
        else:
            cam.panorama_type = "FISHEYE_EQUIDISTANT"
            cam.fisheye_fov = math.pi


def grid_means(path, grid):
    """Means of (R + G + B) / 3 over a grid x grid split of the EXR at `path` (OpenEXR)."""
    import numpy
    import OpenEXR

    with OpenEXR.File(str(path)) as f:
        channels = f.channels()
        key = next(k for k in ("RGB", "RGBA") if k in channels)
        rgb = numpy.asarray(channels[key].pixels, dtype=numpy.float64)
    value = rgb[..., :3].mean(axis=-1)
    height, width = value.shape
    return [[value[r * height // grid:(r + 1) * height // grid,
                   c * width // grid:(c + 1) * width // grid].mean()
             for c in range(grid)] for r in range(grid)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("projection", choices=sorted(CASES))
    parser.add_argument("--rt", default=str(ROOT / "target" / "release" / "rt-cli"))
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--grid", type=int, default=4)
    args = parser.parse_args()
    camera, width, height, flags = CASES[args.projection]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        camera_file = tmp / "camera.json"
        camera_file.write_text(json.dumps(camera))
        rt_out = tmp / "rt.exr"
        subprocess.run(
            [args.rt, "render", "--device", "cpu", "--camera", str(camera_file),
             "--width", str(width), "--height", str(height), "--spp", str(args.spp),
             "--max-depth", "8", "-o", str(rt_out), *flags],
            check=True, capture_output=True)
        scene = build(width, args.spp)
        scene.render.resolution_x, scene.render.resolution_y = width, height
        cycles_camera(scene, args.projection, camera)
        cycles_out = tmp / "cycles.exr"
        scene.render.filepath = str(cycles_out)
        bpy.ops.render.render(write_still=True)
        ours = grid_means(rt_out, args.grid)
        theirs = grid_means(cycles_out, args.grid)
    print(f"{args.projection}: region means, rt / Cycles ({args.grid}x{args.grid}, {args.spp} spp)")
    for row_rt, row_cy in zip(ours, theirs):
        print("  " + "  ".join(
            f"{a:.4f}/{b:.4f}={a / b if b > 1e-6 else float('nan'):.3f}" for a, b in zip(row_rt, row_cy)))


if __name__ == "__main__":
    main()
