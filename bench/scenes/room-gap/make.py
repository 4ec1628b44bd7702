"""Writes room-gap.obj: a closed room (4 × 2.5 × 4, inward-facing grey walls, a red block) whose
only opening is a slit in its −z wall (2 wide, 0.2 high, at 1.6–1.8), for light that enters a room
through a narrow gap. Lit from outside by `--environment sky:35 --env-strength 1` (rt's sun stands
at −z, 35° up: through the slit it lands on the floor mid-room). Run from this folder:
python3 make.py"""

out = ["# bench/scenes/room-gap/make.py", "mtllib room-gap.mtl"]
verts = []


def quad(name, material, a, b, c, d):
    """A quad a-b-c-d, counter-clockwise seen from the side it faces."""
    base = len(verts)
    verts.extend([a, b, c, d])
    out.append(f"o {name}")
    out.append(f"usemtl {material}")
    for p in (a, b, c, d):
        out.append("v %g %g %g" % p)
    i = base + 1
    out.append(f"f {i} {i + 1} {i + 2}")
    out.append(f"f {i} {i + 2} {i + 3}")


X, Y, Z = 2.0, 2.5, 2.0
quad("floor", "wall", (-X, 0, -Z), (-X, 0, Z), (X, 0, Z), (X, 0, -Z))
quad("ceiling", "wall", (-X, Y, -Z), (X, Y, -Z), (X, Y, Z), (-X, Y, Z))
quad("left", "wall", (-X, 0, -Z), (-X, Y, -Z), (-X, Y, Z), (-X, 0, Z))
quad("right", "wall", (X, 0, -Z), (X, 0, Z), (X, Y, Z), (X, Y, -Z))
quad("front", "wall", (-X, 0, Z), (-X, Y, Z), (X, Y, Z), (X, 0, Z))
# The back wall (z = −Z, facing +z) around the slit x ∈ [−1, 1], y ∈ [1.6, 1.8].
x0, x1, y0, y1 = -1.0, 1.0, 1.6, 1.8
quad("back below", "wall", (-X, 0, -Z), (X, 0, -Z), (X, y0, -Z), (-X, y0, -Z))
quad("back above", "wall", (-X, y1, -Z), (X, y1, -Z), (X, Y, -Z), (-X, Y, -Z))
quad("back left", "wall", (-X, y0, -Z), (x0, y0, -Z), (x0, y1, -Z), (-X, y1, -Z))
quad("back right", "wall", (x1, y0, -Z), (X, y0, -Z), (X, y1, -Z), (x1, y1, -Z))
# A block standing in the sunlit patch's way.
bx0, bx1, bz0, bz1, h = -1.4, -0.8, 0.2, 0.8, 0.6
quad("block top", "red", (bx0, h, bz0), (bx0, h, bz1), (bx1, h, bz1), (bx1, h, bz0))
quad("block front", "red", (bx0, 0, bz1), (bx1, 0, bz1), (bx1, h, bz1), (bx0, h, bz1))
quad("block back", "red", (bx0, 0, bz0), (bx0, h, bz0), (bx1, h, bz0), (bx1, 0, bz0))
quad("block left", "red", (bx0, 0, bz0), (bx0, 0, bz1), (bx0, h, bz1), (bx0, h, bz0))
quad("block right", "red", (bx1, 0, bz0), (bx1, h, bz0), (bx1, h, bz1), (bx1, 0, bz1))

with open("room-gap.obj", "w") as f:
    f.write("\n".join(out) + "\n")
