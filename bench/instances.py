#!/usr/bin/env python3
"""Writes a glTF whose nodes all reference one mesh: N instances of an OBJ's triangles on a grid
(the scene of issue 43: instances that should cost nothing). Positions and triangles only.

    python3 bench/instances.py MESH.obj N OUT.gltf
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


def main():
    mesh, count, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    positions, triangles = read_obj(mesh)
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    size = max(hi[k] - lo[k] for k in range(3))
    data = b"".join(struct.pack("<3f", *p) for p in positions)
    index_offset = len(data)
    data += b"".join(struct.pack("<3I", *t) for t in triangles)
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
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": 3 * len(triangles), "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": index_offset},
            {"buffer": 0, "byteOffset": index_offset, "byteLength": len(data) - index_offset},
        ],
        "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                     + base64.b64encode(data).decode()}],
    }
    with open(out, "w", encoding="utf-8") as f:
        json.dump(doc, f)
    print(f"{out}: {count} instances of {len(triangles)} triangles = {count * len(triangles)}")


if __name__ == "__main__":
    main()
