"""The Cornell box of assets/cornell as plain data, for the peer renderers' scripts
(`mitsuba-vs-rt.py`, `cycles_cornell.py`): per-object faces and materials (Kd, Ke) from its OBJ/MTL."""


def parse_cornell(folder):
    """Per-object vertex lists and materials of the Cornell OBJ/MTL."""
    mtl = {}
    current = None
    for line in (folder / "cornell.mtl").read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "newmtl":
            current = parts[1]
            mtl[current] = {}
        elif parts[0] in ("Kd", "Ke") and current:
            values = [float(v) for v in parts[1:4]]
            mtl[current][parts[0]] = values + values[-1:] * (3 - len(values))
    vertices, objects = [], []
    for line in (folder / "cornell.obj").read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            vertices.append([float(v) for v in parts[1:4]])
        elif parts[0] == "o":
            objects.append({"name": parts[1], "faces": [], "material": None})
        elif parts[0] == "usemtl":
            objects[-1]["material"] = parts[1]
        elif parts[0] == "f":
            idx = [int(p.split("/")[0]) for p in parts[1:]]
            idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
            objects[-1]["faces"].append(idx)
    return vertices, objects, mtl
