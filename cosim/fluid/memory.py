"""The memory a liquid will need, checked before it is allocated.

The pair tables dominate: every liquid particle keeps room for ``pair_capacity`` neighbours (283 in 3-D at the
default h = 1.5 dx), each an index and one or two kernel gradients (16 or 28 bytes), and under DFSPH the wall layer
keeps its own; then the two dense cell grids over the domain (8 bytes a cell each). A scene too fine for the machine
(say a 3-D pour at 200 particles across: 3.5 M particles, about 36 GB) is refused with one line before anything is
allocated, instead of being killed by the operating system (or stopped by a traceback from warp's allocator) once
it is.
"""

from __future__ import annotations

import contextlib
import math
from pathlib import Path
from typing import Iterator

import warp as wp

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, PressureSolver
from cosim.fluid.neighbors import grid_counts
from cosim.fluid.sph_common import pair_capacity

INDEX_BYTES = 4  # int32
VECTOR_BYTES = 12  # wp.vec3 of float32
CELL_RANGE_BYTES = 8  # a cell's start and end (int32 each)
MEMINFO = Path("/proc/meminfo")


def liquid_bytes(config: FluidConfig, n_particles: int, n_wall: int) -> int:
    """Bytes of the arrays that grow with the liquid and its resolution: the pair tables and the cell grids of
    the liquid and the walls (exact): a lower bound of what the solver allocates, 97 % of it in 3-D under DFSPH, 83 %
    in 2-D under WCSPH (the per-particle state is the rest; measured in tests/test_fluid_memory.py)."""
    capacity = pair_capacity(config.dim, config.smoothing_ratio)
    dfsph = config.pressure_solver is PressureSolver.DFSPH
    liquid_slot = INDEX_BYTES + VECTOR_BYTES * (2 if dfsph else 1)  # neighbour, grad W (and m grad W)
    wall_slot = INDEX_BYTES + VECTOR_BYTES if dfsph else 0  # the wall layer's own pairs (DFSPH)
    cells = math.prod(grid_counts(config.domain_min, config.domain_max, config.support_radius, config.dim))
    return capacity * (n_particles * liquid_slot + n_wall * wall_slot) + 2 * cells * CELL_RANGE_BYTES


def available_bytes(device: wp.Device) -> int | None:
    """Memory the liquid may take on ``device`` (bytes): the kernel's MemAvailable on a Linux host; on CUDA the
    device's whole memory, not its free memory, which leaves out what earlier liquids of the process freed into
    warp's memory pool and would refuse runs that fit (an allocation that fails all the same is caught by
    :func:`allocation_failure_refused`); None where it cannot be read (no check then)."""
    if device.is_cuda:
        return int(device.total_memory)
    try:
        for line in MEMINFO.read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024  # kB
    except OSError:
        pass
    return None


def check_memory(config: FluidConfig, n_particles: int, n_wall: int, device: wp.Device) -> None:
    """Refuse a liquid whose pair tables and grids alone exceed the memory available on ``device``."""
    need = liquid_bytes(config, n_particles, n_wall)
    have = available_bytes(device)
    if have is not None and need > have:
        raise InputError(
            f"fluid: {n_particles:,} liquid and {n_wall:,} wall particles need at least {need / 1e9:.1f} GB, more than the "
            f"{have / 1e9:.1f} GB {device} can give: choose a coarser resolution (fluid.particles_across)"
        )


@contextlib.contextmanager
def allocation_failure_refused(device: wp.Device) -> Iterator[None]:
    """Turn warp's allocation failure inside the block (a memory limit :func:`check_memory` cannot see, such as
    ``ulimit -v``) into the same kind of one-line error; any other error passes unchanged."""
    try:
        yield
    except RuntimeError as exc:
        if not str(exc).startswith("Failed to allocate"):
            raise
        raise InputError(f"fluid: out of memory on {device} ({exc}): choose a coarser resolution (fluid.particles_across)") from None
