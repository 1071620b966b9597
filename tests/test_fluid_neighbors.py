"""The neighbour loops every SPH sum writes (cosim.fluid.neighbors: neighbor_cells, reachable_cell and the scans
next_liquid_neighbor / next_wall_neighbor, as the module's docstring spells them out) against a brute-force
search: they find exactly the points within the radius, in the one order every SPH sum relies on (cell by cell in
grid order, in each cell the liquid before the wall particles)."""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from cosim.fluid.neighbors import (COINCIDENT_R2, SEEN_ALWAYS, SEEN_FROM_INSIDE, CellGrid, Neighborhood, neighbor_cells, neighborhood,
                                   next_liquid_neighbor, next_wall_neighbor, reachable_cell)

MAX_FOUND = 64
DOMAIN = (0.0, 1.0)
RADIUS = 0.1
NOT_RECORDED = 2**30  # a slot no neighbour was recorded in


@wp.func
def record(found: wp.array2d(dtype=wp.int32), i: int, n: int, code: int) -> int:
    """Neighbour ``code`` recorded as point i's n-th (where there is room); the count after it."""
    if n < MAX_FOUND:
        found[i, 1 + n] = code
    return n + 1


@wp.kernel
def record_walk(
    nb: Neighborhood, radius: float, liquid_only: int, points: wp.array(dtype=wp.vec3), inside: wp.array(dtype=wp.int32),
    found: wp.array2d(dtype=wp.int32),
):
    """The neighbours the loops from each point visit, in the order they visit them (liquid particle j as j, wall
    particle b as -1 - b), after their count in column 0: the liquid and wall loops of the SPH sums (the wall
    particles a point with ``inside`` sees), or with ``liquid_only`` the wall layer's loop over the liquid, which
    counts a liquid particle however near."""
    i = wp.tid()
    x = points[i]
    seen_from = inside[i]
    radius2 = radius * radius
    min_r2 = wp.where(liquid_only != 0, 0.0, COINCIDENT_R2)
    n = int(0)
    cells = neighbor_cells(nb.spec, x)
    for k in range(cells.count):
        cell = reachable_cell(nb, cells, k, x, radius2)
        if cell < 0:
            continue
        liquid_end = nb.cell_end[cell]
        j = next_liquid_neighbor(nb.x, nb.cell_start[cell], liquid_end, x, radius2, min_r2)
        while j < liquid_end:
            n = record(found, i, n, j)
            j = next_liquid_neighbor(nb.x, j + 1, liquid_end, x, radius2, min_r2)
        if liquid_only == 0:
            wall_end = nb.b_cell_end[cell]
            item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, nb.b_cell_start[cell], wall_end, x, seen_from, radius2, min_r2)
            while item < wall_end:
                n = record(found, i, n, -1 - nb.b_order[item])
                item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, item + 1, wall_end, x, seen_from, radius2, min_r2)
    found[i, 0] = n


def seen(sides: np.ndarray, vessels: np.ndarray, inside: int) -> np.ndarray:
    """(n,) bool: the wall particles a point whose vessels are the bits of ``inside`` sees (every particle seen from
    both sides, the others from the side the point is on)."""
    within = (inside >> vessels) & 1
    return (sides == SEEN_ALWAYS) | ((within == 1) == (sides == SEEN_FROM_INSIDE))


def expected_walk(points, x, bx, b_order, cell_of, b_cell_of, walls: bool, min_r2: float, sides, vessels, inside):
    """Brute force: every point within RADIUS (and at least sqrt(min_r2) away; a wall particle only where the point
    sees it), ordered by (cell, liquid before wall, position in its cell list): (kind, index) pairs, kind 1 for a
    wall particle."""
    b_rank = np.empty(len(bx), dtype=int)
    b_rank[b_order] = np.arange(len(bx))
    walks = []
    for p, point_inside in zip(points, inside):
        found = []
        for kind, cloud, cells, rank in ((0, x, cell_of, np.arange(len(x))), (1, bx, b_cell_of, b_rank)):
            if kind == 1 and not walls:
                continue
            d2 = ((p - cloud) ** 2).sum(axis=1)
            visible = seen(sides, vessels, point_inside) if kind == 1 else np.ones(len(cloud), bool)
            for index in np.flatnonzero((d2 >= min_r2) & (d2 < RADIUS**2) & visible):
                found.append((cells[index], kind, rank[index], index))
        walks.append([(kind, int(index)) for _, kind, _, index in sorted(found)])
    return walks


def cell_index(grid: CellGrid, x: np.ndarray) -> np.ndarray:
    """The grid index of each point's cell, computed in float32 as the kernels do."""
    spec = grid.spec
    origin = np.array([spec.origin[0], spec.origin[1], spec.origin[2]], dtype=np.float32)
    counts = np.array([spec.nx, spec.ny, spec.nz])
    c = np.clip(np.floor((x.astype(np.float32) - origin) * np.float32(spec.inv_cell)).astype(int), 0, counts - 1)
    return (c[:, 2] * spec.ny + c[:, 1]) * spec.nx + c[:, 0]


def sorted_points(x: np.ndarray, dim: int, device) -> tuple[CellGrid, wp.array]:
    """The points ``x`` sorted into a cell grid of one radius per cell (the liquid's layout: cell order)."""
    n = len(x)
    grid = CellGrid([DOMAIN[0]] * 3, [DOMAIN[1]] * 3, RADIUS, dim, n, device)
    ones = wp.ones(n, dtype=wp.int32, device=device)
    grid.build(wp.array(x, dtype=wp.vec3, device=device), ones, n)
    x_sorted = wp.array(x[grid.order.numpy()[:n]], dtype=wp.vec3, device=device)
    grid.build(x_sorted, ones, n)
    return grid, x_sorted


def check_walks(x_np: np.ndarray, bx_np: np.ndarray, dim: int, liquid_only: bool, walkers: int, sided: bool = False) -> None:
    """The walk from the first ``walkers`` liquid particles (each leaves itself out) and from every wall particle
    (a wall particle's liquid walk counts a liquid particle put exactly on it) against the brute force; with
    ``sided``, the wall particles seen from either side, inside or outside one of two vessels, and the walkers
    inside neither, either or both, at random."""
    device = "cpu"
    n = len(x_np)
    grid, x = sorted_points(x_np, dim, device)
    bx = wp.array(bx_np, dtype=wp.vec3, device=device)
    wall_grid = CellGrid([DOMAIN[0]] * 3, [DOMAIN[1]] * 3, RADIUS, dim, len(bx_np), device)
    wall_grid.build(bx, wp.ones(len(bx_np), dtype=wp.int32, device=device), len(bx_np))
    rng = np.random.default_rng(7)
    sides = rng.integers(0, 3, len(bx_np)).astype(np.int32) if sided else np.zeros(len(bx_np), np.int32)
    vessels = rng.integers(0, 2, len(bx_np)).astype(np.int32)
    nb = neighborhood(grid, x, wall_grid, bx, wp.array(sides, dtype=wp.int32, device=device), wp.array(vessels, dtype=wp.int32, device=device),
                      wp.zeros(n, dtype=wp.int32, device=device))

    x_np = x.numpy().astype(float)
    points_np = np.concatenate([x_np[:walkers], bx_np.astype(np.float32).astype(float)])
    points_np[-1] = x_np[-1]
    points = wp.array(points_np, dtype=wp.vec3, device=device)
    m = len(points_np)
    inside = rng.integers(0, 4, m).astype(np.int32) if sided else np.zeros(m, np.int32)
    found = wp.full((m, 1 + MAX_FOUND), NOT_RECORDED, dtype=wp.int32, device=device)
    wp.launch(record_walk, m, inputs=[nb, RADIUS, int(liquid_only), points, wp.array(inside, dtype=wp.int32, device=device), found], device=device)

    # distances in float32, as the kernel computes them, so that the brute force agrees on points at the radius
    x32, bx32, points32 = (a.astype(np.float32) for a in (x_np, bx_np, points_np))
    expected = expected_walk(
        points32, x32, bx32, wall_grid.order.numpy()[: len(bx_np)], cell_index(grid, x_np), cell_index(grid, bx_np),
        walls=not liquid_only, min_r2=0.0 if liquid_only else 1.0e-24, sides=sides, vessels=vessels, inside=inside,
    )
    found = found.numpy()
    count = found[:, 0]
    assert count.max() <= MAX_FOUND
    assert count.sum() > 3 * m  # the points have neighbours to find
    if liquid_only:
        assert (found[-1, 1 : 1 + count[-1]] == n - 1).any()  # the liquid particle on the last point is counted
    for k in range(m):
        codes = found[k, 1 : 1 + count[k]]
        assert [(1, -1 - c) if c < 0 else (0, c) for c in codes.tolist()] == expected[k], f"point {k}"


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("liquid_only, sided", [(False, False), (True, False), (False, True)])
def test_walk_visits_the_points_within_the_radius_in_cell_order(dim, liquid_only, sided):
    rng = np.random.default_rng(7 + dim)
    n = 400 if dim == 2 else 1500
    x = rng.uniform(*DOMAIN, (n, 3))
    bx = rng.uniform(*DOMAIN, (n // 3, 3))
    if dim == 2:
        x[:, 1] = bx[:, 1] = 0.0
    check_walks(x, bx, dim, liquid_only, walkers=n // 4, sided=sided)


@pytest.mark.parametrize("dim", [2, 3])
def test_walk_finds_the_points_on_cell_faces_and_beyond_the_grid(dim):
    """The loops leave out the cells of the block that lie beyond the radius (``reachable_cell``): points on
    the cells' faces and corners, a float32 ulp either side of them, and outside the grid (filed in its end cells)
    are found all the same."""
    rng = np.random.default_rng(11 + dim)
    count = 120 if dim == 2 else 600  # a 2-D grid's faces hold fewer distinct points
    faces = RADIUS * rng.integers(0, 11, (count, 3)).astype(float)
    ulp = np.spacing(np.float32(1.0)) * rng.choice([-2.0, -1.0, 0.0, 1.0, 2.0], faces.shape)
    on_faces = (faces.astype(np.float32) * (1.0 + ulp.astype(np.float32))).astype(float)
    near_faces = faces + rng.choice([-1.0, 1.0], faces.shape) * rng.uniform(0.0, 0.02, faces.shape)
    outside = rng.uniform(DOMAIN[0] - 0.15, DOMAIN[1] + 0.15, (count // 2, 3))
    x = np.concatenate([on_faces, near_faces, outside])
    bx = np.concatenate([near_faces[::3], outside[::3]])
    if dim == 2:
        x[:, 1] = bx[:, 1] = 0.0
    check_walks(x, bx, dim, liquid_only=False, walkers=len(x))
