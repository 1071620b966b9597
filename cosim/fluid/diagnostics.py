"""Per-substep diagnostics: layout of the device rows and the host-side record.

Each substep writes one row of floats and one row of ints per lane (atomics: max for maxima, integer adds for counts,
so every field but the energies is order-independent and deterministic on any device; the lanes' rows are combined in
lane order, :func:`combine_lanes`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

# float row
DIAG_MAX_SPEED = wp.constant(0)  # m/s
DIAG_MAX_ACCEL = wp.constant(1)  # m/s^2 (total, gravity included)
DIAG_MAX_DENSITY_ERROR = wp.constant(2)  # max |rho - rho0| / rho0 (DFSPH: compression only, see dfsph.py)
DIAG_KINETIC_ENERGY = wp.constant(3)  # J (3-D equivalent)
DIAG_MAX_COMPRESSION = wp.constant(4)  # max (rho - rho0) / rho0 (the part an instability shows in)
DIAG_DIVERGENCE_ERROR = wp.constant(5)  # DFSPH: average compressing density rate x dt / rho0 left by its solve
DIAG_DENSITY_SOLVE_ERROR = wp.constant(6)  # DFSPH: average predicted compression / rho0 left by its solve
DIAG_POTENTIAL_ENERGY = wp.constant(7)  # J (3-D equivalent), -sum m g . x of the active particles
DIAG_REMOVED_ENERGY = wp.constant(8)  # J, kinetic + potential energy of the particles that left the domain
DIAG_INTERNAL_ENERGY = wp.constant(9)  # J, WCSPH: elastic energy the compressed (or stretched) liquid stores
N_DIAG_FLOAT = 10
# int row
DIAG_NONFINITE = wp.constant(0)  # particles with a non-finite position, velocity or density
DIAG_BREACHES = wp.constant(1)  # wall contacts deeper than max_wall_penetration (instability)
DIAG_CORRECTIONS = wp.constant(2)  # shallow wall contacts corrected by the guard
DIAG_ACTIVE = wp.constant(3)  # active particles after the substep
DIAG_DIVERGENCE_ITERATIONS = wp.constant(4)  # DFSPH: iterations of the divergence solve
DIAG_DENSITY_ITERATIONS = wp.constant(5)  # DFSPH: iterations of the density solve
DIAG_PAIR_OVERFLOW = wp.constant(6)  # particles with more neighbours than the pair list holds (instability)
DIAG_INSIDE0 = wp.constant(7)  # particles inside vessel k at DIAG_INSIDE0 + k
N_DIAG_INT_BASE = 7
# float fields the lanes' rows combine by their maximum (every other field by the sum: counts, energies, and the
# solves' fields, which lane 0 alone writes)
LANE_MAX_FIELDS = (DIAG_MAX_SPEED, DIAG_MAX_ACCEL, DIAG_MAX_DENSITY_ERROR, DIAG_MAX_COMPRESSION)


def read_lane_rows(rows: wp.array, used: int) -> np.ndarray:
    """The first ``used`` rows of every lane of a device's (lanes, rows, fields) diagnostics array, copied to the
    host lane by lane: each lane's leading rows are contiguous, so each is one device-to-host copy of just those
    rows (slicing the rows of all lanes at once would make a non-contiguous view, which warp first copies into a
    new device array)."""
    return np.stack([rows[k, :used].numpy() for k in range(rows.shape[0])])


def replicas_as_lanes(rows: np.ndarray, substeps: int, replicas: int) -> np.ndarray:
    """The first ``substeps`` rows of every lane from an array (lanes, substeps x replicas, fields) whose rows are
    replicated (``cosim.fluid.device_layout``), as (lanes x replicas, substeps, fields): each replica a lane of its
    own for :func:`combine_lanes` (lane-major; with one replica, the rows themselves)."""
    lanes, fields = rows.shape[0], rows.shape[2]
    first = rows[:, : substeps * replicas].reshape(lanes, substeps, replicas, fields)
    return first.transpose(0, 2, 1, 3).reshape(lanes * replicas, substeps, fields)


def combine_lanes(lanes_f: np.ndarray, lanes_i: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows of all lanes (``cosim.fluid.lanes``; arrays (lanes, substeps, fields)) as one row per substep:
    maxima by the maximum, the rest summed over the lanes in lane order."""
    rows_f = lanes_f.sum(axis=0, dtype=lanes_f.dtype)
    rows_f[:, list(LANE_MAX_FIELDS)] = lanes_f[:, :, list(LANE_MAX_FIELDS)].max(axis=0)
    return rows_f, lanes_i.sum(axis=0, dtype=lanes_i.dtype)


@dataclass(frozen=True)
class StepDiagnostics:
    """One substep. Volumes are m^3 (3-D equivalent), counts are particles."""

    step: int
    time: float  # s, at the end of the substep
    dt: float  # s
    max_speed: float  # m/s
    max_acceleration: float  # m/s^2 (DFSPH: of the non-pressure forces; its pressure is implicit)
    max_density_error: float  # max |rho - rho0| / rho0
    max_compression: float  # max (rho - rho0) / rho0
    kinetic_energy: float  # J
    nonfinite: int
    wall_breaches: int
    wall_corrections: int
    active: int
    solver_iterations: tuple[int, int]  # DFSPH (divergence, density) solve iterations; (0, 0) for WCSPH
    volume_in_vessel: tuple[float, ...]  # m^3 per vessel
    spilled_volume: float  # m^3 deactivated (fell below the floor or left the domain)


def rows_to_records(
    first_step: int, t0: float, dt: float, rows_f: np.ndarray, rows_i: np.ndarray, n_total: int, particle_volume: float
) -> list[StepDiagnostics]:
    """Host records of ``len(rows_f)`` consecutive substeps."""
    out = []
    for s in range(rows_f.shape[0]):
        f, i = rows_f[s], rows_i[s]
        out.append(
            StepDiagnostics(
                step=first_step + s,
                time=t0 + (s + 1) * dt,
                dt=dt,
                max_speed=float(f[0]),
                max_acceleration=float(f[1]),
                max_density_error=float(f[2]),
                max_compression=float(f[4]),
                kinetic_energy=float(f[3]),
                nonfinite=int(i[0]),
                wall_breaches=int(i[1]),
                wall_corrections=int(i[2]),
                active=int(i[3]),
                solver_iterations=(int(i[4]), int(i[5])),
                volume_in_vessel=tuple(float(c) * particle_volume for c in i[N_DIAG_INT_BASE:]),
                spilled_volume=(n_total - int(i[3])) * particle_volume,
            )
        )
    return out
