#!/usr/bin/env python3
"""Writes the many-lights room: a 10 x 4 x 10 room with furniture lit by N small one-sided
emissive quads of varied power (three decades, log-uniform) and colour, spread over the
ceiling, the walls and the air in between, as Wavefront OBJ + MTL (Ke = radiance) and a camera
JSON. The light tree's benchmark and test scene (docs/quality.md, "Many lights"). With
--punctual, the same room lit by N point and spot lights instead (KHR_lights_punctual), as
room-punctual.gltf.

    python3 bench/many-lights.py [--lights 1024] [--seed 1] [--out bench/scenes/many-lights]
    python3 bench/many-lights.py --punctual --lights 256

Deterministic for a seed (Python's random.Random). Lights share 32 materials (one object
each), so the scene has 32 light objects whatever N.
"""

import argparse
import base64
import json
import struct
import math
import os
import random

MATERIALS = 32


def quad(centre, normal, size, rng):
    """Four corners of a square of side `size` at `centre` facing `normal` (counter-clockwise
    seen from the front, so the OBJ winding's normal is `normal`)."""
    n = normalize(normal)
    helper = (1.0, 0.0, 0.0) if abs(n[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = normalize(cross(helper, n))
    v = cross(n, u)
    angle = rng.uniform(0, math.pi / 2)
    u, v = (add(scale(u, math.cos(angle)), scale(v, math.sin(angle))),
            add(scale(v, math.cos(angle)), scale(u, -math.sin(angle))))
    h = size / 2
    return [add(centre, add(scale(u, su * h), scale(v, sv * h)))
            for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def scale(a, s):
    return tuple(x * s for x in a)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(a):
    length = math.sqrt(sum(x * x for x in a))
    return tuple(x / length for x in a)


def box(lo, hi):
    """A closed box's six faces as quads, normals outward."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    return [
        [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],  # bottom (-y)
        [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],  # top (+y)
        [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],  # -z
        [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],  # +z
        [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],  # -x
        [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],  # +x
    ]


def room_objects():
    """The room and its furniture: name -> (material, [quads])."""
    objects = {}
    # The room, its faces pointing in (the inside of a box with the winding reversed).
    room = [list(reversed(q)) for q in box((-5, 0, -5), (5, 4, 5))]
    objects["floor"] = ("floor", [room[0]])
    objects["ceiling"] = ("white", [room[1]])
    objects["walls"] = ("white", room[2:4] + [room[5]])
    objects["red wall"] = ("red", [room[4]])
    furniture = [((-3.5, 0, -3.5), (-1.5, 1.0, -2.0)), ((1.0, 0, -4.5), (4.5, 2.2, -3.8)),
                 ((2.0, 0, 0.5), (3.2, 0.8, 1.7)), ((-4.6, 0, 0.0), (-3.8, 3.0, 3.0)),
                 ((-1.0, 0, 1.5), (0.2, 1.6, 2.7)), ((0.5, 2.6, -1.0), (2.5, 2.8, 1.0))]
    objects["furniture"] = ("grey", [q for lo, hi in furniture for q in box(lo, hi)])
    return objects


DIFFUSE = (("floor", (0.45, 0.42, 0.4)), ("white", (0.75, 0.75, 0.75)),
           ("red", (0.6, 0.12, 0.1)), ("grey", (0.5, 0.5, 0.55)))


def write_punctual(args, rng):
    """The room as glTF, lit by point and spot lights (half each; a spot faces into the room,
    its outer cone 30-70 degrees): intensity log-uniform over three decades, warm to cool."""
    materials = [name for name, _ in DIFFUSE]
    positions, indices, primitives = bytearray(), bytearray(), []
    count = 0
    for material, quads in room_objects().values():
        first_index = len(indices) // 4
        for q in quads:
            for p in q:
                positions += struct.pack("<3f", *p)
            indices += struct.pack("<6I", count, count + 1, count + 2, count, count + 2, count + 3)
            count += 4
        primitives.append((materials.index(material), first_index, len(indices) // 4 - first_index))
    lights, nodes = [], [{"mesh": 0}]
    for i in range(args.lights):
        where = rng.random()
        if where < 0.35:
            centre, normal = (rng.uniform(-4.8, 4.8), 3.9, rng.uniform(-4.8, 4.8)), (0.0, -1.0, 0.0)
        elif where < 0.7:
            t, y = rng.uniform(-4.8, 4.8), rng.uniform(0.3, 3.8)
            centre, normal = [((t, y, -4.9), (0, 0, 1)), ((t, y, 4.9), (0, 0, -1)),
                              ((-4.9, y, t), (1, 0, 0)), ((4.9, y, t), (-1, 0, 0))][rng.randrange(4)]
        else:
            centre = (rng.uniform(-4.5, 4.5), rng.uniform(0.3, 3.7), rng.uniform(-4.5, 4.5))
            normal = normalize((rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, 1)))
        warm = rng.random()
        # Candela: about the power of one of the emissive room's lamps (683 lm/W).
        light = {"color": [1.0, 0.75 + 0.25 * warm, 0.5 + 0.5 * warm],
                 "intensity": round(683 * 0.004 * 10 ** rng.uniform(-1.0, 2.0), 3)}
        node = {"translation": list(centre), "extensions": {"KHR_lights_punctual": {"light": i}}}
        if i % 2:
            outer = math.radians(rng.uniform(30, 70))
            light.update(type="spot", spot={"innerConeAngle": outer * rng.uniform(0.3, 0.9),
                                            "outerConeAngle": outer})
            # The rotation taking a spot's -z onto the normal, (a x b, 1 + a.b) normalised (half
            # a turn about x where they are opposite).
            a = (0.0, 0.0, -1.0)
            q = (*cross(a, normal), 1.0 + sum(x * y for x, y in zip(a, normal)))
            node["rotation"] = list(normalize(q)) if q[3] > 1e-6 else [1.0, 0.0, 0.0, 0.0]
        else:
            light["type"] = "point"
        lights.append(light)
        nodes.append(node)
    buffer = bytes(positions) + bytes(indices)
    gltf = {
        "asset": {"version": "2.0", "generator": f"bench/many-lights.py --punctual --lights {args.lights} --seed {args.seed}"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1 + k, "material": m}
                                   for k, (m, _, _) in enumerate(primitives)]}],
        "materials": [{"name": name, "pbrMetallicRoughness": {"baseColorFactor": [*kd, 1.0],
                       "metallicFactor": 0.0, "roughnessFactor": 1.0}} for name, kd in DIFFUSE],
        "buffers": [{"byteLength": len(buffer),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(buffer).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(positions), "target": 34962},
                        {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices),
                         "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
                       "min": [-5, 0, -5], "max": [5, 4, 5]}]
        + [{"bufferView": 1, "byteOffset": 4 * first, "componentType": 5125, "count": n, "type": "SCALAR"}
           for _, first, n in primitives],
    }
    with open(os.path.join(args.out, "room-punctual.gltf"), "w") as f:
        json.dump(gltf, f)
        f.write("\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lights", type=int, default=1024)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", default="bench/scenes/many-lights")
    parser.add_argument("--punctual", action="store_true")
    args = parser.parse_args()
    rng = random.Random(args.seed)
    os.makedirs(args.out, exist_ok=True)
    if args.punctual:
        write_punctual(args, rng)
        return
    objects = room_objects()

    groups = [[] for _ in range(MATERIALS)]
    for _ in range(args.lights):
        where = rng.random()
        size = rng.uniform(0.06, 0.2)
        if where < 0.35:  # ceiling, facing down
            centre = (rng.uniform(-4.8, 4.8), 3.995, rng.uniform(-4.8, 4.8))
            normal = (0.0, -1.0, 0.0)
        elif where < 0.7:  # a wall, facing into the room
            side = rng.randrange(4)
            t, y = rng.uniform(-4.8, 4.8), rng.uniform(0.3, 3.8)
            centre, normal = [((t, y, -4.995), (0, 0, 1)), ((t, y, 4.995), (0, 0, -1)),
                              ((-4.995, y, t), (1, 0, 0)), ((4.995, y, t), (-1, 0, 0))][side]
        else:  # in the air, facing anywhere
            centre = (rng.uniform(-4.5, 4.5), rng.uniform(0.3, 3.7), rng.uniform(-4.5, 4.5))
            normal = normalize((rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, 1)))
        groups[rng.randrange(MATERIALS)].append(quad(centre, normal, size, rng))
    for i, quads in enumerate(groups):
        if quads:
            objects[f"lights {i:02}"] = (f"light{i:02}", quads)

    with open(os.path.join(args.out, "room.mtl"), "w") as mtl:
        mtl.write(f"# many-lights room (bench/many-lights.py --lights {args.lights} --seed {args.seed})\n")
        for name, kd in DIFFUSE:
            mtl.write(f"newmtl {name}\nKd {kd[0]} {kd[1]} {kd[2]}\n\n")
        for i in range(MATERIALS):
            # Radiance over three decades, log-uniform; a warm-to-cool tint.
            strength = 10 ** rng.uniform(-1.0, 2.0)
            warm = rng.random()
            colour = (1.0, 0.75 + 0.25 * warm, 0.5 + 0.5 * warm)
            ke = " ".join(f"{c * strength:.4f}" for c in colour)
            mtl.write(f"newmtl light{i:02}\nKd 0 0 0\nKe {ke}\n\n")

    with open(os.path.join(args.out, "room.obj"), "w") as obj:
        obj.write(f"# many-lights room (bench/many-lights.py --lights {args.lights} --seed {args.seed})\n")
        obj.write("mtllib room.mtl\n")
        base = 1
        for name, (material, quads) in objects.items():
            obj.write(f"o {name}\nusemtl {material}\n")
            for q in quads:
                for p in q:
                    obj.write("v {:.4f} {:.4f} {:.4f}\n".format(*p))
            for k in range(len(quads)):
                i = base + 4 * k
                obj.write(f"f {i} {i + 1} {i + 2} {i + 3}\n")
            base += 4 * len(quads)

    with open(os.path.join(args.out, "camera.json"), "w") as cam:
        json.dump({"from": [4.6, 2.2, 4.6], "to": [-1.0, 1.4, -1.5], "up": [0, 1, 0],
                   "vfov": 60, "width": 320, "height": 240, "background": [0, 0, 0]}, cam)
        cam.write("\n")


if __name__ == "__main__":
    main()
