"""Writes glass-caustics.obj: a smooth glass sphere, a mirror sphere and a diffuse sphere on a
floor before a back wall, under a small area light (a scene of the kind where Russian roulette
and caustic paths decide the error; bench/README.md). Run from this folder: python3 make.py"""
import math

def sphere(out, vbase, nbase, cx, cy, cz, r, n_lat=24, n_lon=48):
    verts, faces = [], []
    for i in range(n_lat + 1):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            verts.append((math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)))
    for i in range(n_lat):
        for j in range(n_lon):
            a = i * n_lon + j
            b = i * n_lon + (j + 1) % n_lon
            c = (i + 1) * n_lon + (j + 1) % n_lon
            d = (i + 1) * n_lon + j
            if i > 0:
                faces.append((a, b, c))
            if i < n_lat - 1:
                faces.append((a, c, d))
    for (x, y, z) in verts:
        out.append(f"v {cx + r * x:.6f} {cy + r * y:.6f} {cz + r * z:.6f}")
    for (x, y, z) in verts:
        out.append(f"vn {x:.6f} {y:.6f} {z:.6f}")
    for f in faces:
        # These wind clockwise seen from outside, against the outward normals (a slip kept on
        # purpose: a mesh like it must render by its normals, crates/core/tests/winding.rs).
        a, b, c = (k + 1 for k in (f[0], f[2], f[1]))
        out.append(f"f {vbase + a}//{nbase + a} {vbase + b}//{nbase + b} {vbase + c}//{nbase + c}")
    return vbase + len(verts), nbase + len(verts)

out = ["# bench/scenes/glass-caustics/make.py", "mtllib glass-caustics.mtl"]
v = 0
out += ["o floor", "usemtl floor",
        "v -6 0 -4", "v 6 0 -4", "v 6 0 6", "v -6 0 6",
        "f 1 4 3", "f 1 3 2"]
v += 4
out += ["o back", "usemtl wall",
        "v -6 0 -4", "v 6 0 -4", "v 6 6 -4", "v -6 6 -4",
        f"f {v+1} {v+2} {v+3}", f"f {v+1} {v+3} {v+4}"]
v += 4
# A 0.6 x 0.6 light facing down at height 4.
out += ["o light", "usemtl light",
        "v -0.3 4 -0.3", "v 0.3 4 -0.3", "v 0.3 4 0.3", "v -0.3 4 0.3",
        f"f {v+1} {v+2} {v+3}", f"f {v+1} {v+3} {v+4}"]
v += 4
n = 0
out += ["o glass", "usemtl glass"]
v, n = sphere(out, v, n, -1.3, 0.8, 0.5, 0.8)
out += ["o mirror", "usemtl mirror"]
v, n = sphere(out, v, n, 0.6, 0.7, -1.0, 0.7)
out += ["o diffuse", "usemtl diffuse"]
v, n = sphere(out, v, n, 1.6, 0.5, 1.0, 0.5)
open("glass-caustics.obj", "w").write("\n".join(out) + "\n")
