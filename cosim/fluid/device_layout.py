"""How the solver lays out its neighbour-pair tables and its reductions for the kind of device it runs on.

The CPU runs a particle kernel as one loop per lane (``cosim.fluid.lanes``): a particle's data should be contiguous
for the cache. CUDA runs a thread per particle in warps of 32 that load together: the same field of 32 neighbouring
particles should be contiguous (coalesced loads), and no one address should take an atomic from every particle.
A kernel profile on a GPU (``python -m cosim.bench.kernel_profile``, 3-D WCSPH at 1M particles; figures in
docs/benchmarks.md) shows all three costs: the pair loops reading rows of the pair tables, the wrench reduction's
sequential chunks and integrate's atomics on one diagnostics row.

- Pair tables (n x capacity, indexed ``[i, k]``): a row per particle on the CPU; on CUDA stored slot-major
  (capacity x n) and passed transposed, so ``[i, k]`` of 32 consecutive particles is 32 consecutive addresses. The
  kernels are the same: a warp array's strides carry the layout. Slot-major helps the kernels that read the tables
  in lock step and slows the ones that write them and DFSPH's Gauss-Seidel sweeps (a colour runs a 27th of the
  cells), so a solver that sweeps keeps a row per particle on CUDA too (``python -m cosim.bench.kernel_profile
  --pair-layouts rows columns`` compares the two; the figures are in docs/performance.md). DFSPH's tables are flat
  and read through each particle's first slot (``cosim.fluid.pair_slots``): on the CPU packed, the lists of each
  block of 16 particles one after the other, so a pass reads one stream per block rather than a mostly empty row
  per particle.
- Pair tables at all (WCSPH): the substep's first walk (``update_free_liquid``) writes them and the force pass
  and the density rate read them back; without them (``pair_tables`` False) those two walk the cells again, the
  neighbours on the fly from the cell ranges as DualSPHysics does, and the same sums come out in the same order.
  Every device keeps them: on CUDA a second walk cost more than the tables' writes and reads when the force pass
  wrote them (``python -m cosim.bench.kernel_profile --pair-layouts columns none``; the figures are in
  docs/benchmarks.md); on the CPU the force pass is cheaper over the tables than walking (docs/performance.md).
- The wall wrench (a sum over every particle per vessel, in a fixed order): on the CPU :data:`WRENCH_CHUNKS`
  contiguous chunks; on CUDA levels of chunks of :data:`REDUCTION_ITEMS` interleaved items (chunk c sums items c,
  c + chunks, ...: consecutive threads read consecutive addresses), until few enough partial sums remain.
- Accumulators every particle adds to atomically (each substep's diagnostics row, DFSPH's solve statistics): on
  CUDA replicated :data:`CUDA_ATOMIC_REPLICAS` times, particle i adding to replica i mod replicas, so each address
  takes 1/replicas of the atomics; the replicas are combined as the lanes are (maxima by the maximum, the rest
  summed: on the host for the diagnostics, in ``dfsph.check_convergence`` for the statistics, integers there).

The particle state is the same bit for bit under either layout; the wrench and the energy sums add the same terms
in another order (tests/test_fluid_device_layout.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import warp as wp

WRENCH_CHUNKS = 64  # CPU: contiguous first-level chunks of the fixed-order wrench reduction
REDUCTION_ITEMS = 64  # CUDA: items one thread sums per level of the interleaved reduction
CUDA_ATOMIC_REPLICAS = 64  # CUDA: replicas of each accumulator (atomics per address divided by this)


@dataclass(frozen=True)
class DeviceLayout:
    """pairs_by_column: pair tables slot-major (CUDA) instead of particle-major. pairs_packed: DFSPH's
    particle-major tables packed by blocks of particles (the CPU's; each block built in order by one thread, which a
    CUDA launch does not do) instead of a row per particle. interleaved_reduction: the
    wrench reduced in interleaved levels (CUDA) instead of contiguous chunks. atomic_replicas: copies of each
    accumulator (diagnostics row, solve statistics) the particles spread their atomics over. pair_tables: WCSPH's
    force pass and density rate sum over the pair tables its first walk writes; False: each walks the cells again
    and computes the kernel gradients anew (no tables written, read or allocated; DFSPH's solve reads its tables
    many times a substep and always keeps them)."""

    pairs_by_column: bool
    pairs_packed: bool
    interleaved_reduction: bool
    atomic_replicas: int
    pair_tables: bool = True


CPU_LAYOUT = DeviceLayout(pairs_by_column=False, pairs_packed=True, interleaved_reduction=False, atomic_replicas=1)
CUDA_LAYOUT = DeviceLayout(pairs_by_column=True, pairs_packed=False, interleaved_reduction=True, atomic_replicas=CUDA_ATOMIC_REPLICAS)
CUDA_SWEEP_LAYOUT = replace(CUDA_LAYOUT, pairs_by_column=False)  # CUDA's, the pair tables a row per particle


def layout_for(device, sweeps: bool = False) -> DeviceLayout:
    """The layout for a warp device; ``sweeps``: the solver's density solve runs Gauss-Seidel sweeps by cell colour
    (a row per particle in the pair tables on CUDA too)."""
    if not device.is_cuda:
        return CPU_LAYOUT
    return CUDA_SWEEP_LAYOUT if sweeps else CUDA_LAYOUT


def pair_table(rows: int, capacity: int, dtype, device, by_column: bool) -> wp.array:
    """A zeroed ``rows x capacity`` table indexed ``[row, slot]``, stored slot-major when ``by_column``."""
    if by_column:
        return wp.zeros((capacity, rows), dtype=dtype, device=device).transpose()
    return wp.zeros((rows, capacity), dtype=dtype, device=device)


@dataclass(frozen=True)
class ReductionLevel:
    """One level: ``chunks`` partial sums of a list of ``length`` items; chunk c sums the items
    c * first_stride + j * item_stride for j < items (those below ``length``), in that order."""

    length: int
    chunks: int
    first_stride: int
    item_stride: int
    items: int


def reduction_levels(n: int, interleaved: bool) -> list[ReductionLevel]:
    """The levels that reduce ``n`` items to at most :data:`WRENCH_CHUNKS` (contiguous) or
    :data:`REDUCTION_ITEMS` (interleaved) partial sums, which a last pass adds in order."""
    if not interleaved:
        chunk = math.ceil(n / WRENCH_CHUNKS)
        return [ReductionLevel(n, WRENCH_CHUNKS, chunk, 1, chunk)]
    levels, length = [], n
    while length > REDUCTION_ITEMS:
        chunks = math.ceil(length / REDUCTION_ITEMS)
        levels.append(ReductionLevel(length, chunks, 1, chunks, REDUCTION_ITEMS))
        length = chunks
    return levels
