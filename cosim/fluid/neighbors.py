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
def block_cell(g: GridSpec, block: CellBlock, k: int) -> int:
    """Grid index of the k-th cell of ``block`` (0 <= k < ``block.count``), x fastest, then y, then z: every
    neighbour loop visits the cells, and so sums its neighbours, in this one order. The neighbour loop reads

        cells = neighbor_cells(g, x)
        for k in range(cells.count):
            cell = block_cell(g, cells, k)
            for j in range(cell_start[cell], cell_end[cell]): ..."""
    sx = block.size[0]
    sy = block.size[1]
    cx = block.first[0] + k % sx
    cy = block.first[1] + (k // sx) % sy
    cz = block.first[2] + k // (sx * sy)
    return grid_index(g, cx, cy, cz)


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
