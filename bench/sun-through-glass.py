"""A sun through a glass ball onto a floor: rt's `--integrator bdpt` against Mitsuba 3's particle
tracer (`ptracer`), region by region (the caustic, the ball's shadow, the lit floor), and the lit
floor against its closed form E·ρ/π.

The ball (radius 1, smooth glass of index 1.5, a 48 × 96 sphere with smooth normals) stands with
its centre 1.5 above the floor: a ball lens focuses at n R / (2 (n − 1)) = 1.5 R behind its
centre, so the sun's caustic lands on the floor. The sun shines straight down with irradiance 1
W/m² (683 lux in glTF); the floor is diffuse with albedo 0.8. Both renderers read the same
triangles (the glTF rt opens and the OBJ files Mitsuba opens are written from one list).

With --sky the sun is part of an environment map instead (rt's light subpaths then start from the
environment): a 512 × 256 equirectangular sky of radiance 0.2 with a sun at the zenith whose
radiance falls off as a Gaussian of 3° (smooth, so Mitsuba's bilinear look-ups and rt's nearest
texel see the same light), read by rt as `--environment` and by Mitsuba as an `envmap`. The two
read an image's rows at different angles: rt's row r covers θ from r·π/H to (r+1)·π/H (its value
is the radiance at the row's centre), Mitsuba's row r is the radiance at θ = r·π/(H−1) (the
first and last rows at the poles). Each gets the same continuous sky sampled its way (written
alike, a sun this near the pole would differ by 13% in irradiance).

Run: python3 bench/sun-through-glass.py OUT_DIR --cli target/release/rt-cli [--spp 256]
      [--mitsuba-spp 256] [--size 256] [--sky]
Needs: pip install mitsuba==3.9.1 numpy (and Debian's libllvm19 for the llvm variant).
"""
import argparse
import base64
import json
import math
import os
import struct
import subprocess
import sys

import numpy as np

CENTRE_Y = 1.5
RADIUS = 1.0
FLOOR = 5.0
ALBEDO = 0.8
CAMERA_FROM = (0.0, 3.0, 7.0)
CAMERA_TO = (0.0, 0.3, 0.0)
VFOV = 35.0


def sphere(n_lat=48, n_lon=96):
    verts, normals, tris = [], [], []
    for i in range(n_lat + 1):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            normals.append(n)
            verts.append((RADIUS * n[0], CENTRE_Y + RADIUS * n[1], RADIUS * n[2]))
    for i in range(n_lat):
        for j in range(n_lon):
            a = i * n_lon + j
            b = i * n_lon + (j + 1) % n_lon
            c = (i + 1) * n_lon + (j + 1) % n_lon
            d = (i + 1) * n_lon + j
            # Counter-clockwise seen from outside: the winding agrees with the normals.
            if i > 0:
                tris.append((a, b, c))
            if i < n_lat - 1:
                tris.append((a, c, d))
    return verts, normals, tris


def floor():
    f = FLOOR
    verts = [(-f, 0, -f), (f, 0, -f), (f, 0, f), (-f, 0, f)]
    return verts, [(0, 1, 0)] * 4, [(0, 2, 1), (0, 3, 2)]


def write_obj(path, mesh):
    verts, normals, tris = mesh
    with open(path, "w") as out:
        for v in verts:
            out.write("v %.7f %.7f %.7f\n" % v)
        for n in normals:
            out.write("vn %.7f %.7f %.7f\n" % n)
        for t in tris:
            out.write("f %d//%d %d//%d %d//%d\n" % tuple(k + 1 for k in t for _ in (0, 1)))


def look_at_quaternion(eye, target):
    """The rotation taking glTF's camera (looking down −z, up +y) to look from eye at target."""
    f = np.array(target, float) - np.array(eye, float)
    f /= np.linalg.norm(f)
    r = np.cross(f, [0.0, 1.0, 0.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.stack([r, u, -f], axis=1)  # columns: the camera's x, y, z in the world
    w = math.sqrt(max(0.0, 1 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = (m[2, 1] - m[1, 2]) / (4 * w)
    y = (m[0, 2] - m[2, 0]) / (4 * w)
    z = (m[1, 0] - m[0, 1]) / (4 * w)
    return [x, y, z, w]


SKY = 0.2
SUN_PEAK = 2000.0
SUN_SIGMA_DEG = 3.0


def sky_texels(mitsuba, width=512, height=256):
    """The --sky environment, rows from +y (the zenith) down, as float32 RGB: sampled at rt's row
    centres, or at Mitsuba's rows (`mitsuba`)."""
    rows = np.arange(height)
    theta = rows / (height - 1) * 180.0 if mitsuba else (rows + 0.5) / height * 180.0
    row = sky_radiance(theta)
    return np.repeat(np.repeat(row[:, None, None], width, axis=1), 3, axis=2).astype(np.float32)


def sky_radiance(theta_deg):
    return SKY + SUN_PEAK * np.exp(-0.5 * (theta_deg / SUN_SIGMA_DEG) ** 2)


def sky_irradiance():
    """E = ∫ L(θ) cosθ dω over the upper hemisphere, of the continuous sky."""
    t = np.linspace(0.0, math.pi / 2, 200001)
    f = sky_radiance(np.degrees(t)) * np.cos(t) * np.sin(t)
    return 2 * math.pi * float(np.sum((f[1:] + f[:-1]) * 0.5 * np.diff(t)))


def write_gltf(path, meshes, size, sun=True):
    blob = b""
    accessors, views, gl_meshes = [], [], []
    for k, (verts, normals, tris) in enumerate(meshes):
        for data, kind in ((verts, "VEC3"), (normals, "VEC3")):
            start = len(blob)
            blob += b"".join(struct.pack("<3f", *v) for v in data)
            views.append({"buffer": 0, "byteOffset": start, "byteLength": len(blob) - start})
            arr = np.array(data)
            accessors.append({"bufferView": len(views) - 1, "componentType": 5126,
                              "count": len(data), "type": kind,
                              "min": arr.min(0).tolist(), "max": arr.max(0).tolist()})
        start = len(blob)
        blob += b"".join(struct.pack("<3I", *t) for t in tris)
        views.append({"buffer": 0, "byteOffset": start, "byteLength": len(blob) - start})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5125,
                          "count": 3 * len(tris), "type": "SCALAR"})
        gl_meshes.append({"primitives": [{"attributes": {"POSITION": 3 * k, "NORMAL": 3 * k + 1},
                                          "indices": 3 * k + 2, "material": k}]})
    # The light points along its node's −z: turned −90° about x, it shines straight down.
    down = [-math.sin(math.pi / 4), 0.0, 0.0, math.cos(math.pi / 4)]
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_transmission", "KHR_materials_ior",
                           "KHR_materials_volume", "KHR_materials_specular"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "intensity": 683.0, "color": [1, 1, 1]}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3] if sun else [0, 1, 3]}],
        "nodes": [
            {"mesh": 0, "name": "floor"},
            {"mesh": 1, "name": "ball"},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "rotation": down, "name": "sun"},
            {"camera": 0, "translation": list(CAMERA_FROM),
             "rotation": look_at_quaternion(CAMERA_FROM, CAMERA_TO), "name": "camera"},
        ],
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": math.radians(VFOV), "aspectRatio": 1.0, "znear": 0.01}}],
        "materials": [
            # No specular layer: a Lambertian floor, as Mitsuba's `diffuse`.
            {"name": "floor", "pbrMetallicRoughness": {
                "baseColorFactor": [ALBEDO, ALBEDO, ALBEDO, 1], "metallicFactor": 0,
                "roughnessFactor": 1},
             "extensions": {"KHR_materials_specular": {"specularFactor": 0}}},
            {"name": "glass", "pbrMetallicRoughness": {
                "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0},
             # A volume makes it a solid ball (without one glTF's transmission is a thin shell).
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                            "KHR_materials_ior": {"ior": 1.5},
                            "KHR_materials_volume": {"thicknessFactor": 2.0}}},
        ],
        "meshes": gl_meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    }
    with open(path, "w") as out:
        json.dump(doc, out)


def mitsuba_render(out_dir, size, spp, sky):
    import mitsuba as mi
    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception:
        mi.set_variant("scalar_rgb")
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "ptracer", "max_depth": 8, "hide_emitters": True},
        "sensor": {"type": "perspective", "fov": VFOV, "fov_axis": "y",
                   "to_world": mi.ScalarTransform4f().look_at(
                       origin=CAMERA_FROM, target=CAMERA_TO, up=[0, 1, 0]),
                   "film": {"type": "hdrfilm", "width": size, "height": size,
                            "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "sun": {"type": "envmap", "filename": sky} if sky else {
            "type": "directional", "direction": [0, -1, 0],
            "irradiance": {"type": "rgb", "value": [1, 1, 1]}},
        "floor": {"type": "obj", "filename": os.path.join(out_dir, "floor.obj"),
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [ALBEDO] * 3}}},
        "ball": {"type": "obj", "filename": os.path.join(out_dir, "ball.obj"),
                 "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}},
    })
    image = mi.render(scene)
    path = os.path.join(out_dir, "mitsuba.exr")
    mi.util.write_bitmap(path, image, write_async=False)
    return np.array(image)[:, :, :3]


def read_exr(path):
    import mitsuba as mi
    return np.array(mi.Bitmap(path))[:, :, :3]


def project(point, size):
    """Pixel (x, y) of a world point in the camera above."""
    eye, target = np.array(CAMERA_FROM), np.array(CAMERA_TO)
    f = (target - eye) / np.linalg.norm(target - eye)
    r = np.cross(f, [0, 1, 0]); r /= np.linalg.norm(r)
    u = np.cross(r, f)
    d = np.array(point) - eye
    depth = d @ f
    t = math.tan(math.radians(VFOV) / 2)
    px, py = (d @ r) / depth / t, (d @ u) / depth / t
    return (px + 1) / 2 * size, (1 - py) / 2 * size


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("out")
    p.add_argument("--cli", default="target/release/rt-cli")
    p.add_argument("--size", type=int, default=256)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--mitsuba-spp", type=int, default=256)
    p.add_argument("--sky", action="store_true", help="the sun in an environment map")
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    ball, ground = sphere(), floor()
    write_obj(os.path.join(a.out, "ball.obj"), ball)
    write_obj(os.path.join(a.out, "floor.obj"), ground)
    gltf = os.path.join(a.out, "sun-glass.gltf")
    write_gltf(gltf, [ground, ball], a.size, sun=not a.sky)
    sky = None
    if a.sky:
        import mitsuba as mi
        mi.set_variant("scalar_rgb")
        sky = os.path.join(a.out, "sky.exr")
        mi.Bitmap(sky_texels(mitsuba=False)).write(sky)
        mi.Bitmap(sky_texels(mitsuba=True)).write(os.path.join(a.out, "sky-mitsuba.exr"))
    ref = mitsuba_render(a.out, a.size, a.mitsuba_spp,
                         sky and os.path.join(a.out, "sky-mitsuba.exr"))
    def render_rt(integrator):
        out = os.path.join(a.out, f"rt-{integrator}.exr")
        subprocess.run([a.cli, "render", gltf, "--integrator", integrator, "--device", "cpu",
                        "--environment", sky or "none", "--width", str(a.size), "--height",
                        str(a.size), "--max-depth", "8", "--spp", str(a.spp), "-o", out],
                       check=True)
        return read_exr(out)

    rt, path = render_rt("bdpt"), render_rt("path")
    def box(points):
        xy = np.array([project(q, a.size) for q in points])
        return xy[:, 0].min(), xy[:, 1].min(), xy[:, 0].max(), xy[:, 1].max()

    def around(x, z, r):
        return box([(x - r, 0, z), (x + r, 0, z), (x, 0, z - r), (x, 0, z + r)])

    regions = {
        "focus (r 0.15)": around(0, 0, 0.15),
        "under the ball (r 1.1)": around(0, 0, 1.1),
        "lit floor": around(-1.2, 1.5, 0.25),
    }
    print(f"{'region':<24} {'rt bdpt':>10} {'Mitsuba':>10} {'ratio':>8} {'rt path':>10}")
    for name, (x0, y0, x1, y1) in regions.items():
        window = (slice(int(y0), int(y1) + 1), slice(int(x0), int(x1) + 1))
        mine, theirs = rt[window].mean(), ref[window].mean()
        print(f"{name:<24} {mine:10.5f} {theirs:10.5f} {mine / theirs:8.4f} "
              f"{path[window].mean():10.5f}")
    print(f"{'whole image':<24} {rt.mean():10.5f} {ref.mean():10.5f} {rt.mean() / ref.mean():8.4f}")
    irradiance = sky_irradiance() if a.sky else 1.0
    print(f"lit floor closed form E·ρ/π = {ALBEDO * irradiance / math.pi:.5f} (without the light "
          "the ball reflects onto it)")


if __name__ == "__main__":
    sys.exit(main())
