"""Write the example mug (examples/meshes/mug.obj), a box vessel as a mesh (examples/meshes/beaker.obj) and a flared
cup (examples/meshes/flared_cup.obj).

The mug: a revolved wall profile (80 mm inside, 100 mm from the inner floor to the rim, 4 mm walls, a 6 mm floor with
a rounded outer edge) and a C-shaped handle of round section on the -x side, opposite the pour direction (+x). The
handle's ends sink into the wall, so the mesh is two closed solids that overlap there: watertight, which is what
cosim needs. The box: examples/small_beaker.toml's beaker (inner 80 x 60 mm, 0.10 m high, 3 mm walls), to pour it as
a mesh and as dimensions. The flared cup: walls widening from 60 mm across the floor to 90 mm at the rim, 90 mm high,
a vessel whose slosh has no closed form. Metres, opening up.

    python examples/meshes/make_mug.py [OUT_DIR]
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import trimesh

INNER_RADIUS = 0.040  # m
INNER_HEIGHT = 0.100  # m, inner floor to rim
WALL = 0.004  # m
FLOOR = 0.006  # m
SEGMENTS = 48  # around the axis
HANDLE_RADIUS = 0.030  # m, the handle's arc, centred at the wall's outer face
HANDLE_THICKNESS = 0.006  # m, the handle's round section's radius


def mug_body() -> trimesh.Trimesh:
    """The revolved wall: the profile (r, z) from the axis under the floor, round the outside, over the rim, down the
    inside and back to the axis on the inner floor."""
    outer = INNER_RADIUS + WALL
    fillet = [(outer - 0.004 + 0.004 * math.sin(a), -FLOOR + 0.004 - 0.004 * math.cos(a)) for a in np.linspace(0, math.pi / 2, 5)]
    profile = [(0.0, -FLOOR)] + fillet + [(outer, INNER_HEIGHT), (INNER_RADIUS, INNER_HEIGHT), (INNER_RADIUS, 0.0), (0.0, 0.0)]
    body = trimesh.creation.revolve(np.array(profile), sections=SEGMENTS)
    if body.volume < 0:
        body.invert()
    return body


def handle() -> trimesh.Trimesh:
    """A tube of radius HANDLE_THICKNESS along a C-shaped arc in the x-z plane on the -x side, ends capped."""
    centre = np.array([-(INNER_RADIUS + WALL) + 0.004, 0.0, 0.5 * INNER_HEIGHT])
    arcs = np.linspace(math.radians(100), math.radians(260), 24)
    ring = np.linspace(0, 2 * math.pi, 16, endpoint=False)
    rings = []
    for a in arcs:
        c = centre + HANDLE_RADIUS * np.array([math.cos(a), 0.0, math.sin(a)])
        radial = np.array([math.cos(a), 0.0, math.sin(a)])
        rings.append(c + HANDLE_THICKNESS * (np.cos(ring)[:, None] * radial + np.sin(ring)[:, None] * np.array([0.0, 1.0, 0.0])))
    vertices = np.concatenate(rings + [[rings[0].mean(axis=0)], [rings[-1].mean(axis=0)]])
    n, k = len(ring), len(arcs)
    faces = []
    for i in range(k - 1):
        for j in range(n):
            a, b, c, d = i * n + j, i * n + (j + 1) % n, (i + 1) * n + j, (i + 1) * n + (j + 1) % n
            faces += [[a, c, b], [b, c, d]]
    first, last = k * n, k * n + 1
    faces += [[first, j, (j + 1) % n] for j in range(n)]
    faces += [[last, (k - 1) * n + (j + 1) % n, (k - 1) * n + j] for j in range(n)]
    tube = trimesh.Trimesh(vertices, np.array(faces), process=True)
    if tube.volume < 0:
        tube.invert()
    return tube


def flared_cup() -> trimesh.Trimesh:
    """A revolved cup whose inner radius grows linearly from 30 mm at the floor to 45 mm at the rim, 3 mm walls."""
    profile = [(0.0, -0.004), (0.033, -0.004), (0.048, 0.09), (0.045, 0.09), (0.030, 0.0), (0.0, 0.0)]
    cup = trimesh.creation.revolve(np.array(profile), sections=SEGMENTS)
    if cup.volume < 0:
        cup.invert()
    return cup


def box_vessel(width=0.08, depth=0.06, height=0.10, wall=0.003) -> trimesh.Trimesh:
    """An open box: the outer block less the cavity, as one closed solid."""
    b, d = 0.5 * width, 0.5 * depth
    outer = [(-b - wall, -d - wall), (b + wall, -d - wall), (b + wall, d + wall), (-b - wall, d + wall)]
    inner = [(-b, -d), (b, -d), (b, d), (-b, d)]
    v = [(x, y, -wall) for x, y in outer] + [(x, y, height) for x, y in outer] + [(x, y, height) for x, y in inner] + [(x, y, 0.0) for x, y in inner]
    f = [[0, 2, 1], [0, 3, 2]]  # bottom (down)
    for i in range(4):
        j = (i + 1) % 4
        f += [[i, j, 4 + j], [i, 4 + j, 4 + i]]  # outer sides
        f += [[4 + i, 4 + j, 8 + j], [4 + i, 8 + j, 8 + i]]  # rim top
        f += [[8 + i, 8 + j, 12 + j], [8 + i, 12 + j, 12 + i]]  # inner sides (facing in)
    f += [[12, 13, 14], [12, 14, 15]]  # inner floor (up)
    mesh = trimesh.Trimesh(np.array(v), np.array(f), process=True)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    mug = trimesh.util.concatenate([mug_body(), handle()])
    mug.export(out / "mug.obj")
    box_vessel().export(out / "beaker.obj")
    flared_cup().export(out / "flared_cup.obj")
    print(f"wrote {out / 'mug.obj'} ({len(mug.faces)} faces), {out / 'beaker.obj'} and {out / 'flared_cup.obj'}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent)
