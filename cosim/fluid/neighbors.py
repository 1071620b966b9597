"""Neighbour search: a sorted cell list on a dense grid over the domain.

Cells are one kernel support (2h) wide, so a particle's neighbours lie in the 3 x 3 (2-D, the grid is one cell
thick in y) or 3 x 3 x 3 (3-D) block of cells around it. Each build sorts particles by cell (warp's radix sort,
stable, so the order is deterministic) and records each cell's [start, end) range in the sorted order; the
caller reorders its particle arrays by the returned permutation, so neighbours are contiguous in memory.
Chosen over ``wp.HashGrid`` because the 2-D query visits 9 cells instead of 27 and the reorder makes neighbour
access coherent (measured in docs/benchmarks.md).

The cell ranges must be reset before each build. :attr:`GridReset.OCCUPIED` clears only the cells the previous
build occupied (from its sorted keys): O(points), so the grid costs what the region holding the liquid (or the
walls) needs, however large the domain. :attr:`GridReset.WHOLE` clears every cell of the domain: O(cells). Both
leave the same ranges, so the neighbour lists, and every result, are identical.

Every SPH sum over neighbours walks the same cells in the same order, written out as nested loops over a
:class:`Neighborhood`, the liquid and the wall particles in one grid::

    cells = neighbor_cells(nb.spec, xi)
    for k in range(cells.count):
        cell = reachable_cell(nb, cells, k, xi, radius2)
        if cell < 0:
            continue
        liquid_end = nb.cell_end[cell]                                  # the liquid, in cell order
        j = next_liquid_neighbor(nb.x, nb.cell_start[cell], liquid_end, xi, radius2, COINCIDENT_R2)
        while j < liquid_end:
            r = xi - nb.x[j]
            r2 = wp.dot(r, r)
            ...
            j = next_liquid_neighbor(nb.x, j + 1, liquid_end, xi, radius2, COINCIDENT_R2)
        wall_end = nb.b_cell_end[cell]                                  # then the cell's wall particles
        item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, nb.b_cell_start[cell], wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)
        while item < wall_end:                                          # those the particle sees (wall_seen)
            b = nb.b_order[item]
            ...
            item = next_wall_neighbor(nb.b_order, nb.bx, nb.b_side, nb.b_vessel, item + 1, wall_end, xi, nb.inside[i], radius2, COINCIDENT_R2)

(a body must not ``continue``: the loop advances at its end). So every kernel adds its terms in one order, cell
by cell, in each the liquid before the walls. Each cell's candidates are scanned by a tight loop of their own
(:func:`next_liquid_neighbor`; about four of five candidates lie outside the support) and the body runs only for
a neighbour. Loops, not an iterator: on CUDA a walk kept in a struct and advanced by a function (in the manner of
warp's ``hash_grid_query_next``) made the same sums markedly slower than plain nested loops; on the CPU a plain
loop with the body inside the candidate loop was slower than the walk, which the separate scan avoids (``python -m
cosim.bench.kernel_profile``; the figures are in docs/benchmarks.md). The loops open only the cells of the block
whose box lies within the radius (:func:`reachable_cell`, :func:`cell_within_reach`): a support sphere reaches
20.6 of the 27 cells on average in 3-D (1 + 6 + 12 pi/4 + 8 pi/6 for a point uniformly placed in its cell; 8.1 of
9 in 2-D), so in a uniform liquid 4.9 points are tested per neighbour instead of 6.5, and the neighbours and their
order stay the same.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
import warp as wp

from cosim.fluid.config import GridReset
from cosim.fluid.launch import record_launch


@wp.struct
class GridSpec:
    """Dense cell grid: ``origin`` (m, world), ``inv_cell`` (1/m), cell counts per axis."""

    origin: wp.vec3
    inv_cell: float
    nx: int
    ny: int
    nz: int


@wp.func
def grid_cell(g: GridSpec, x: wp.vec3) -> wp.vec3i:
    """Cell coordinates of a world point, clamped into the grid (points outside map to edge cells)."""
    cx = wp.clamp(int(wp.floor((x[0] - g.origin[0]) * g.inv_cell)), 0, g.nx - 1)
    cy = wp.clamp(int(wp.floor((x[1] - g.origin[1]) * g.inv_cell)), 0, g.ny - 1)
    cz = wp.clamp(int(wp.floor((x[2] - g.origin[2]) * g.inv_cell)), 0, g.nz - 1)
    return wp.vec3i(cx, cy, cz)


@wp.func
def grid_index(g: GridSpec, cx: int, cy: int, cz: int) -> int:
    return (cz * g.ny + cy) * g.nx + cx


@wp.struct
class CellBlock:
    """The cells a neighbour loop visits around a point: the 3 x 3 x 3 block of cells centred on the point's cell
    (one cell thick in y in 2-D), cut at the grid's faces. ``first``: the lowest cell's coordinates; ``size``: cells
    along each axis; ``count``: their product."""

    first: wp.vec3i
    size: wp.vec3i
    count: int


@wp.func
def neighbor_cells(g: GridSpec, x: wp.vec3) -> CellBlock:
    """The block of cells that holds every neighbour within one support of x (cells are one support wide)."""
    c = grid_cell(g, x)
    lo = wp.vec3i(wp.max(c[0] - 1, 0), wp.max(c[1] - 1, 0), wp.max(c[2] - 1, 0))
    hi = wp.vec3i(wp.min(c[0] + 1, g.nx - 1), wp.min(c[1] + 1, g.ny - 1), wp.min(c[2] + 1, g.nz - 1))
    block = CellBlock()
    block.first = lo
    block.size = hi - lo + wp.vec3i(1, 1, 1)
    block.count = block.size[0] * block.size[1] * block.size[2]
    return block


@wp.func
def block_cell_coords(block: CellBlock, k: int) -> wp.vec3i:
    """Cell coordinates of the k-th cell of ``block`` (0 <= k < ``block.count``), x fastest, then y, then z: the
    neighbour loops (:func:`reachable_cell`) visit the cells, and so sum the neighbours, in this one order."""
    sx = block.size[0]
    sy = block.size[1]
    return wp.vec3i(block.first[0] + k % sx, block.first[1] + (k // sx) % sy, block.first[2] + k // (sx * sy))


# Slack (in cells) by which a cell's box is widened before it is found out of reach: a point is filed by the floor
# of its rounded cell coordinate, so it may lie a few ulps outside its cell's exact box, and the loops' own
# distance test rounds too; 1e-3 of a cell is far above both and keeps every cell the loops could find a
# neighbour in.
CELL_REACH_SLACK = wp.constant(1.0e-3)


@wp.func
def axis_gap(g: GridSpec, c: int, last: int, origin: float, x: float) -> float:
    """Distance (m) along one axis from ``x`` to the slab of cell ``c`` of a grid axis with cells 0..``last``,
    the slab widened by :data:`CELL_REACH_SLACK` and unbounded outward at the grid's end cells, which hold every
    point beyond them (:func:`grid_cell` clamps)."""
    size = 1.0 / g.inv_cell
    lo = origin + (float(c) - CELL_REACH_SLACK) * size
    hi = origin + (float(c + 1) + CELL_REACH_SLACK) * size
    gap = float(0.0)
    if c > 0 and x < lo:
        gap = lo - x
    if c < last and x > hi:
        gap = x - hi
    return gap


@wp.func
def cell_within_reach(g: GridSpec, c: wp.vec3i, x: wp.vec3, radius2: float) -> bool:
    """Whether any point filed in cell ``c`` can lie within sqrt(``radius2``) (m) of ``x``: the squared distance
    from x to the cell's box (:func:`axis_gap`) below radius2. The corner and edge cells of a 3 x 3 x 3 block
    around a point reach its support sphere only where the point lies near them (about 6 of the 27 cells are out
    of reach on average in 3-D, about 1 of 9 in 2-D); skipping them leaves the neighbours and their order as
    they are."""
    gx = axis_gap(g, c[0], g.nx - 1, g.origin[0], x[0])
    gy = axis_gap(g, c[1], g.ny - 1, g.origin[1], x[1])
    gz = axis_gap(g, c[2], g.nz - 1, g.origin[2], x[2])
    return gx * gx + gy * gy + gz * gz < radius2


@wp.struct
class Neighborhood:
    """The liquid and the wall particles sorted into one cell grid ``spec``, as the neighbour loops read them: the
    liquid in cell order (``x``, m; ``cell_start``/``cell_end``: each cell's range of it), the wall particles by
    indirection (``b_order``: their indices in cell order; ``b_cell_start``/``b_cell_end``: each cell's range of
    ``b_order``; ``bx``, m), with which liquid sees each (``b_side``, ``b_vessel``: :func:`wall_seen`) and, for
    each liquid particle in cell order, the vessels whose inner volume holds it (``inside``, bit v for vessel v;
    written only where a wall is seen from one side, :func:`mark_inside_vessels`)."""

    spec: GridSpec
    cell_start: wp.array(dtype=wp.int32)
    cell_end: wp.array(dtype=wp.int32)
    x: wp.array(dtype=wp.vec3)
    b_order: wp.array(dtype=wp.int32)
    b_cell_start: wp.array(dtype=wp.int32)
    b_cell_end: wp.array(dtype=wp.int32)
    bx: wp.array(dtype=wp.vec3)
    b_side: wp.array(dtype=wp.int32)
    b_vessel: wp.array(dtype=wp.int32)
    inside: wp.array(dtype=wp.int32)


# Below this squared distance (m^2) a point is taken to be at x itself (the particle whose neighbours are summed),
# where the pair's direction is undefined
COINCIDENT_R2 = wp.constant(1.0e-24)


@wp.func
def reachable_cell(nb: Neighborhood, cells: CellBlock, k: int, x: wp.vec3, radius2: float) -> int:
    """The grid index of the k-th cell of ``cells`` (:func:`block_cell_coords`' order), or -1 where no point filed
    in it can lie within sqrt(``radius2``) (m) of ``x`` (:func:`cell_within_reach`): neither its liquid nor its
    wall particles are then opened."""
    c = block_cell_coords(cells, k)
    if cell_within_reach(nb.spec, c, x, radius2):
        return grid_index(nb.spec, c[0], c[1], c[2])
    return -1


@wp.func
def within_support(r2: float, radius2: float, min_r2: float) -> bool:
    """Whether a point at squared distance ``r2`` (m^2) is a neighbour: ``min_r2`` <= r2 < ``radius2``
    (:data:`COINCIDENT_R2` leaves the particle itself out; 0 counts every point however near)."""
    return not (r2 >= radius2 or r2 < min_r2)


@wp.func
def next_liquid_neighbor(points: wp.array(dtype=wp.vec3), item: int, end: int, x: wp.vec3, radius2: float, min_r2: float) -> int:
    """The first of ``points`` (the liquid, ``Neighborhood.x``) from ``item`` on, before ``end`` (a cell's range of
    it), that is a neighbour of ``x`` (:func:`within_support`); ``end`` where none is. The arrays, not the whole
    :class:`Neighborhood`, are passed: a function call may copy its arguments."""
    j = item
    while j < end:
        r = x - points[j]
        if within_support(wp.dot(r, r), radius2, min_r2):
            return j
        j += 1
    return end


# Which liquid sees a wall particle (Neighborhood.b_side; cosim.fluid.wall_sampling.wall_sides): all of it, only the
# liquid inside the particle's vessel, only the liquid outside it
SEEN_ALWAYS = wp.constant(0)
SEEN_FROM_INSIDE = wp.constant(1)
SEEN_FROM_OUTSIDE = wp.constant(2)
# The ``inside`` of a point that sees every wall particle (a wall particle's own sums, a solver without sided walls)
SEES_EVERY_WALL = wp.constant(-1)


@wp.func
def wall_seen(side: int, vessel: int, inside: int) -> bool:
    """Whether a point whose ``inside`` holds bit v for each vessel v whose inner volume holds it (or is
    :data:`SEES_EVERY_WALL`) sees a wall particle of vessel ``vessel`` seen from ``side``."""
    if inside < 0 or side == SEEN_ALWAYS:
        return True
    within = (inside >> vessel) & 1
    return (within == 1) == (side == SEEN_FROM_INSIDE)


@wp.func
def next_wall_neighbor(
    order: wp.array(dtype=wp.int32), points: wp.array(dtype=wp.vec3), sides: wp.array(dtype=wp.int32), vessel_of: wp.array(dtype=wp.int32),
    item: int, end: int, x: wp.vec3, inside: int, radius2: float, min_r2: float,
) -> int:
    """The first item of ``order`` (``Neighborhood.b_order``) from ``item`` on, before ``end`` (a cell's range of it),
    whose wall particle in ``points`` (``Neighborhood.bx``) is a neighbour of ``x`` (:func:`within_support`) that a
    point with ``inside`` sees (:func:`wall_seen`, ``sides`` and ``vessel_of`` the Neighborhood's); ``end`` where
    none is."""
    j = item
    while j < end:
        b = order[j]
        r = x - points[b]
        if within_support(wp.dot(r, r), radius2, min_r2):
            if wall_seen(sides[b], vessel_of[b], inside):
                return j
        j += 1
    return end


@wp.kernel
def compute_cell_keys(
    # Model
    g: GridSpec,
    # State in
    x: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    # Out
    keys: wp.array(dtype=wp.int32),
    order: wp.array(dtype=wp.int32),
):
    """Sort keys: the cell index of each active particle; inactive ones get the sentinel n_cells (sorted last)."""
    i = wp.tid()
    if active[i] != 0:
        c = grid_cell(g, x[i])
        keys[i] = grid_index(g, c[0], c[1], c[2])
    else:
        keys[i] = g.nx * g.ny * g.nz
    order[i] = i


@wp.kernel
def find_cell_ranges(
    # Model
    n: int,
    n_cells: int,
    # State in
    keys: wp.array(dtype=wp.int32),
    # Out
    cell_start: wp.array(dtype=wp.int32),
    cell_end: wp.array(dtype=wp.int32),
):
    """[start, end) of each occupied cell in the sorted order (cells must be zeroed before)."""
    i = wp.tid()
    k = keys[i]
    if k >= n_cells:
        return
    if i == 0 or keys[i - 1] != k:
        cell_start[k] = i
    if i == n - 1 or keys[i + 1] != k:
        cell_end[k] = i + 1


@wp.kernel
def clear_occupied_cells(
    # Model
    n_cells: int,
    # State in
    keys: wp.array(dtype=wp.int32),
    # Out
    cell_start: wp.array(dtype=wp.int32),
    cell_end: wp.array(dtype=wp.int32),
):
    """Zero the range of the cell each point occupied in the previous build (its sorted key; sentinels skipped)."""
    k = keys[wp.tid()]
    if k < n_cells:
        cell_start[k] = 0
        cell_end[k] = 0


def grid_counts(domain_min, domain_max, cell_size: float, dim: int) -> list[int]:
    """Cells per axis of the dense grid over the domain (one cell thick in y in 2-D)."""
    lo = np.asarray(domain_min, dtype=float)
    hi = np.asarray(domain_max, dtype=float)
    counts = [max(1, math.ceil((hi[a] - lo[a]) / cell_size)) for a in range(3)]
    if dim == 2:
        counts[1] = 1
    return counts


class CellGrid:
    """A reusable sorted cell list for up to ``capacity`` points.

    After :meth:`build`, ``order[i]`` is the index (in the input arrays) of the i-th point in cell order, and
    ``cell_start``/``cell_end`` give each cell's range in that order.
    """

    def __init__(self, domain_min, domain_max, cell_size: float, dim: int, capacity: int, device, reset: GridReset = GridReset.OCCUPIED):
        lo = np.asarray(domain_min, dtype=float).copy()
        counts = grid_counts(domain_min, domain_max, cell_size, dim)
        if dim == 2:
            lo[1] = -0.5 * cell_size
        self.spec = GridSpec()
        self.spec.origin = wp.vec3(*lo)
        self.spec.inv_cell = 1.0 / cell_size
        self.spec.nx, self.spec.ny, self.spec.nz = counts
        self.n_cells = counts[0] * counts[1] * counts[2]
        self.capacity = capacity
        self.device = device
        self.reset = reset
        n2 = max(2 * capacity, 2)
        self.keys = wp.full(n2, self.n_cells, dtype=wp.int32, device=device)  # sentinels: no cell occupied yet
        self.order = wp.zeros(n2, dtype=wp.int32, device=device)
        self.cell_start = wp.zeros(self.n_cells, dtype=wp.int32, device=device)
        self.cell_end = wp.zeros(self.n_cells, dtype=wp.int32, device=device)

    @property
    def key_bits(self) -> int:
        """Bits the sort keys need (cell indices and the n_cells sentinel): the radix sort does no more passes."""
        return max(1, self.n_cells.bit_length())

    def build_commands(self, x: wp.array, active: wp.array, n: int) -> list[Callable[[], None]]:
        """The operations that sort the first ``n`` points of ``x`` by cell and record the cell ranges, with their
        arguments bound once (recorded launches), to be run in order every build."""
        if n == 0:
            return [self.cell_start.zero_, self.cell_end.zero_]
        keys = record_launch(compute_cell_keys, n, self.device, dict(g=self.spec, x=x, active=active, keys=self.keys, order=self.order))
        ranges = record_launch(
            find_cell_ranges, n, self.device, dict(n=n, n_cells=self.n_cells, keys=self.keys, cell_start=self.cell_start, cell_end=self.cell_end)
        )
        bits = self.key_bits

        def sort() -> None:
            wp.utils.radix_sort_pairs(self.keys, self.order, n, 0, bits)

        if self.reset is GridReset.WHOLE:
            return [keys, sort, self.cell_start.zero_, self.cell_end.zero_, ranges]
        clear = record_launch(clear_occupied_cells, n, self.device, dict(n_cells=self.n_cells, keys=self.keys, cell_start=self.cell_start, cell_end=self.cell_end))
        return [clear, keys, sort, ranges]

    def build(self, x: wp.array, active: wp.array, n: int) -> None:
        """Sort the first ``n`` points by cell and record the cell ranges (one-off; loops use build_commands)."""
        for op in self.build_commands(x, active, n):
            op()


def neighborhood(grid: CellGrid, x: wp.array, wall_grid: CellGrid, bx: wp.array, b_side: wp.array, b_vessel: wp.array, inside: wp.array) -> Neighborhood:
    """The :class:`Neighborhood` of the liquid at ``x`` (in the cell order of ``grid``; ``inside`` its vessels) and
    of the wall particles at ``bx`` (sorted by ``wall_grid``, which must have the same cells; ``b_side``,
    ``b_vessel``: which liquid sees each)."""
    nb = Neighborhood()
    nb.spec = grid.spec
    nb.cell_start = grid.cell_start
    nb.cell_end = grid.cell_end
    nb.x = x
    nb.b_order = wall_grid.order
    nb.b_cell_start = wall_grid.cell_start
    nb.b_cell_end = wall_grid.cell_end
    nb.bx = bx
    nb.b_side = b_side
    nb.b_vessel = b_vessel
    nb.inside = inside
    return nb
