"""Where each particle's pair-list entries lie in DFSPH's flat pair tables.

A particle's k-th entry is at slot ``start[i] + k * step`` of each table (the neighbour's index, its kernel
gradient, that times its mass). Three layouts, the same entries in the same order under each:

- packed (the CPU's): the particles of each block of :data:`PAIR_BLOCK` consecutive particles store their entries
  one after the other, from the block's first slot (block * PAIR_BLOCK * capacity) on, so a pass over the pair list
  reads one contiguous stream per block instead of a row per particle that is mostly empty (a 3-D support holds
  about 110 neighbours, a row 2.5 times the lattice's 113: each row read would start a new stream that the
  hardware prefetcher has to find again; docs/performance.md has the measurements). The builder keeps each
  block's next free slot while it walks; the particles of a block must be built one after the
  other, in order, by one thread, which holds on the CPU (a launch runs its threads in order, and the lanes deal
  out chunks of ``cosim.fluid.lanes.LANE_CHUNK`` = PAIR_BLOCK particles, ``cosim.fluid.lanes.lane_item``);
- rows: particle i's entries at i * capacity, one after the other (CUDA's Gauss-Seidel solve);
- columns: entry k of every particle side by side (``cosim.fluid.device_layout``, CUDA's Jacobi solve: a warp of
  threads reads consecutive addresses).

Each block (or row) has room for ``capacity`` entries a particle, so no layout runs out of slots before the
particle's own capacity does.
"""

from __future__ import annotations

import warp as wp

from cosim.fluid.lanes import LANE_CHUNK

PAIR_BLOCK = LANE_CHUNK
# A block's next free slot sits this many int32 after the previous block's (64 bytes, a cache line): neighbouring
# blocks belong to different lanes, and two lanes' cursors in one line would pass it between the cores on every
# particle (false sharing)
BLOCK_NEXT_STRIDE = 16


@wp.struct
class PairSlots:
    """``start`` (N,): each particle's first slot; ``step``: the slots between its consecutive entries; ``stride``:
    a fixed layout's slots between consecutive particles' first entries (0: packed by blocks); ``capacity``: entries
    a particle may have; ``block_next`` (blocks x :data:`BLOCK_NEXT_STRIDE`,): a packed build's next free slot of each
    block, at its first entry."""

    start: wp.array(dtype=wp.int32)
    step: int
    stride: int
    capacity: int
    block_next: wp.array(dtype=wp.int32)


@wp.func
def open_pair_row(slots: PairSlots, i: int) -> int:
    """Particle i's first slot, recorded in ``slots.start``, as its list is built (packed: the block's next free
    slot, the block's first slot for its first particle)."""
    first = i * slots.stride
    if slots.stride == 0:
        block = i // PAIR_BLOCK
        if i % PAIR_BLOCK == 0:
            slots.block_next[block * BLOCK_NEXT_STRIDE] = block * PAIR_BLOCK * slots.capacity
        first = slots.block_next[block * BLOCK_NEXT_STRIDE]
    slots.start[i] = first
    return first


@wp.func
def close_pair_row(slots: PairSlots, i: int, first: int, count: int):
    """Particle i's list built with ``count`` entries: a packed block's next particle starts after them."""
    if slots.stride == 0:
        slots.block_next[(i // PAIR_BLOCK) * BLOCK_NEXT_STRIDE] = first + count * slots.step


def pair_slots(rows: int, capacity: int, device, by_column: bool, packed: bool) -> PairSlots:
    """The slots of ``rows`` particles' lists of up to ``capacity`` entries: by columns, else packed by blocks
    (``packed``, the CPU only), else rows (``cosim.fluid.device_layout.DeviceLayout``). Its tables are
    :func:`flat_pair_table` (rows x capacity slots)."""
    if packed and not by_column and wp.get_device(device).is_cuda:
        raise ValueError("packed pair lists need a device that runs a launch's threads in order (the CPU)")
    slots = PairSlots()
    slots.start = wp.zeros(max(rows, 1), dtype=wp.int32, device=device)
    slots.capacity = capacity
    slots.block_next = wp.zeros(max(-(-rows // PAIR_BLOCK), 1) * BLOCK_NEXT_STRIDE, dtype=wp.int32, device=device)
    if by_column:
        slots.step, slots.stride = max(rows, 1), 1
    elif packed:
        slots.step, slots.stride = 1, 0
    else:
        slots.step, slots.stride = 1, capacity
    return slots


def flat_pair_table(rows: int, capacity: int, dtype, device) -> wp.array:
    """A zeroed table of ``rows x capacity`` slots (indexed through :class:`PairSlots`)."""
    return wp.zeros(max(rows * capacity, 1), dtype=dtype, device=device)
