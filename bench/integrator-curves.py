"""relMSE against time of `--integrator path` and `--integrator bdpt` on four scenes, for
docs/quality.md: the Cornell box (against Mitsuba 3's 8192-spp reference), glass-caustics
(bench/scenes: smooth glass, mirror and diffuse spheres under a small area light), a sun through a
glass ball (the glTF bench/sun-through-glass.py writes) and room-gap (bench/scenes: a room lit
through a slit by the physical sky's sun). 128², depth 8, `--device cpu`, one series at a time.

The references other than the Cornell box's are rt's own long renders, with another seed, by the
integrator that converges faster on that scene (its residual error is in every point of both
curves alike). Each series doubles its samples from 1 to the count that takes about `--seconds`
on the machine these were set on (a 2-core AMD EPYC VM); the printed table gives each
integrator's relMSE at the longest time both reached, interpolated log-log.

Run: python3 bench/integrator-curves.py [--cli target/release/rt-cli] [--out docs/data]
      [--cornell-reference ../shared/scenes/cornell/reference_mitsuba_8192spp.exr]
Needs: numpy.
"""
import argparse
import csv
import importlib.util
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SIZE = 128


def scenes(cornell_reference, work):
    spec = importlib.util.spec_from_file_location(
        "sun_through_glass", os.path.join(ROOT, "bench", "sun-through-glass.py"))
    sun = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sun)
    gltf = os.path.join(work, "sun-glass.gltf")
    sun.write_gltf(gltf, [sun.floor(), sun.sphere()], SIZE)
    scenes_dir = os.path.join(ROOT, "bench", "scenes")
    return [
        # name, scene arguments, reference (a file, or (integrator, spp) to render), max spp
        # of path and of bdpt.
        ("cornell", [], cornell_reference, 2048, 512),
        ("glass-caustics",
         [os.path.join(scenes_dir, "glass-caustics", "glass-caustics.obj"),
          "--camera", os.path.join(scenes_dir, "glass-caustics", "camera.json")],
         ("bdpt", 16384), 4096, 2048),
        ("sun-through-glass", [gltf, "--environment", "none"], ("bdpt", 8192), 2048, 1024),
        ("room-gap",
         [os.path.join(scenes_dir, "room-gap", "room-gap.obj"),
          "--camera", os.path.join(scenes_dir, "room-gap", "camera.json"),
          "--environment", "sky:35", "--env-strength", "1"],
         ("path", 16384), 1024, 1024),
    ]


def run(cmd):
    print("+", " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)


def read_series(path):
    series = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            series.setdefault(row["label"], []).append(
                (float(row["seconds"]), float(row["rel_mse"])))
    return series


def at_time(points, t):
    """relMSE at time t, interpolated between the points around it in log-log."""
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if t0 <= t <= t1:
            f = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp(math.log(e0) + f * (math.log(e1) - math.log(e0)))
    return float("nan")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--cli", default=os.path.join(ROOT, "target", "release", "rt-cli"))
    p.add_argument("--out", default=os.path.join(ROOT, "docs", "data"))
    p.add_argument("--work", default="/tmp/rt-integrator-curves")
    p.add_argument("--cornell-reference", default=os.path.join(
        ROOT, "..", "shared", "scenes", "cornell", "reference_mitsuba_8192spp.exr"))
    p.add_argument("--only", help="one scene by name")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    os.makedirs(a.work, exist_ok=True)
    common = ["--width", str(SIZE), "--height", str(SIZE), "--max-depth", "8",
              "--device", "cpu"]
    rows = []
    for name, scene, reference, path_spp, bdpt_spp in scenes(a.cornell_reference, a.work):
        if a.only and name != a.only:
            continue
        if isinstance(reference, tuple):
            integrator, spp = reference
            file = os.path.join(a.work, f"{name}-reference.exr")
            if not os.path.exists(file):
                run([a.cli, "render", *scene, *common, "--integrator", integrator, "--spp",
                     str(spp), "--no-adaptive", "--seed", "4242", "-o", file])
            reference = file
        if not os.path.exists(reference):
            sys.exit(f"no reference at {reference} (pass --cornell-reference)")
        table = os.path.join(a.out, f"bdpt-{name}.csv")
        if os.path.exists(table):
            os.remove(table)
        for integrator, spp in (("path", path_spp), ("bdpt", bdpt_spp)):
            run([a.cli, "converge", *scene, *common, "--integrator", integrator,
                 "--reference", reference, "--max-spp", str(spp), "--label", integrator,
                 "--csv", table])
        run([a.cli, "plot", table, "-o", os.path.join(a.out, f"bdpt-{name}.svg"),
             "--title", f"{name} {SIZE}x{SIZE}: relMSE against time, path and bdpt (CPU)"])
        series = read_series(table)
        t = min(series["path"][-1][0], series["bdpt"][-1][0])
        e_path, e_bdpt = at_time(series["path"], t), at_time(series["bdpt"], t)
        rows.append((name, t, e_path, e_bdpt))
    print(f"\n| scene | at (s) | path relMSE | bdpt relMSE | bdpt / path |\n|---|---|---|---|---|")
    for name, t, e_path, e_bdpt in rows:
        print(f"| {name} | {t:.1f} | {e_path:.3e} | {e_bdpt:.3e} | {e_bdpt / e_path:.2f} |")


if __name__ == "__main__":
    sys.exit(main())
