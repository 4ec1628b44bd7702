#!/usr/bin/env python3
"""Writes a glTF whose nodes all reference one mesh: N instances of an OBJ's triangles on a grid
(the scene of issue 43: instances that should cost nothing). Positions and triangles, and with
--normals smooth vertex normals (area-weighted, as a mesh exported with smooth shading has).

    python3 bench/instances.py [--normals] MESH.obj N OUT.gltf
"""
import base64
import json
import math
import struct
import sys


def read_obj(path):
    positions, triangles = [], []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] == "v":
                positions.append(tuple(float(w) for w in words[1:4]))
            elif words[0] == "f":
                corners = [int(w.split("/")[0]) for w in words[1:]]
                corners = [c - 1 if c > 0 else len(positions) + c for c in corners]
                for i in range(1, len(corners) - 1):
                    triangles.append((corners[0], corners[i], corners[i + 1]))
    return positions, triangles


def smooth_normals(positions, triangles):
    sums = [[0.0, 0.0, 0.0] for _ in positions]
    for t in triangles:
        a, b, c = (positions[i] for i in t)
        u = [b[k] - a[k] for k in range(3)]
        v = [c[k] - a[k] for k in range(3)]
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        for i in t:
            for k in range(3):
                sums[i][k] += n[k]
    out = []
    for s in sums:
        length = math.sqrt(sum(x * x for x in s))
        out.append(tuple(x / length for x in s) if length > 0 else (0.0, 1.0, 0.0))
    return out


def main():
    args = sys.argv[1:]
    normals = "--normals" in args
    args = [a for a in args if a != "--normals"]
    mesh, count, out = args[0], int(args[1]), args[2]
    positions, triangles = read_obj(mesh)
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    size = max(hi[k] - lo[k] for k in range(3))
    data = b"".join(struct.pack("<3f", *p) for p in positions)
    index_offset = len(data)
    data += b"".join(struct.pack("<3I", *t) for t in triangles)
    attributes = {"POSITION": 0}
    accessors_extra, views_extra = [], []
    if normals:
        normal_offset = len(data)
        data += b"".join(struct.pack("<3f", *n) for n in smooth_normals(positions, triangles))
        attributes["NORMAL"] = 2
        accessors_extra.append(
            {"bufferView": 2, "componentType": 5126, "count": len(positions), "type": "VEC3"})
        views_extra.append(
            {"buffer": 0, "byteOffset": normal_offset, "byteLength": len(data) - normal_offset})
    side = math.ceil(math.sqrt(count))
    nodes = [
        {"mesh": 0, "translation": [(i % side) * size * 1.2, 0.0, (i // side) * size * 1.2]}
        for i in range(count)
    ]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": list(range(count))}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": 3 * len(triangles), "type": "SCALAR"},
        ] + accessors_extra,
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": index_offset},
            {"buffer": 0, "byteOffset": index_offset,
             "byteLength": (normal_offset if normals else len(data)) - index_offset},
        ] + views_extra,
        "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                     + base64.b64encode(data).decode()}],
    }
    with open(out, "w", encoding="utf-8") as f:
        json.dump(doc, f)
    print(f"{out}: {count} instances of {len(triangles)} triangles = {count * len(triangles)}")


if __name__ == "__main__":
    main()
