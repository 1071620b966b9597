"""Per-substep diagnostics: layout of the device rows and the host-side record.

Each substep writes one row of floats and one row of ints per lane (atomics: max for maxima, integer adds for counts,
so every field but the energies is order-independent and deterministic on any device; the lanes' rows are combined in
lane order, :func:`combine_lanes`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

from cosim.fluid.lanes import PerLane

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
    if replicas == 1:
        return rows[:, :substeps]
    lanes, fields = rows.shape[0], rows.shape[2]
    first = rows[:, : substeps * replicas].reshape(lanes, substeps, replicas, fields)
    return first.transpose(0, 2, 1, 3).reshape(lanes * replicas, substeps, fields)


_LANE_MAX_COLUMNS = np.array(LANE_MAX_FIELDS)


def combine_lanes(lanes_f: np.ndarray, lanes_i: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows of all lanes (``cosim.fluid.lanes``; arrays (lanes, substeps, fields)) as one row per substep:
    maxima by the maximum, the rest summed over the lanes in lane order. One lane's rows are copied as they are (a
    sum or maximum over one lane is its value)."""
    if lanes_f.shape[0] == 1:
        return lanes_f[0].copy(), lanes_i[0].copy()
    rows_f = lanes_f.sum(axis=0, dtype=lanes_f.dtype)
    rows_f[:, _LANE_MAX_COLUMNS] = lanes_f[:, :, _LANE_MAX_COLUMNS].max(axis=0)
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


def _float_field(column: int, doc: str) -> property:
    return property(lambda rows: rows.f[:, column], doc=doc)


def _int_field(column: int, doc: str) -> property:
    return property(lambda rows: rows.i[:, column], doc=doc)


@dataclass(frozen=True)
class SubstepRows:
    """Consecutive substeps' diagnostics, the lanes combined: ``f`` (substeps, N_DIAG_FLOAT) and ``i`` (substeps,
    N_DIAG_INT_BASE + vessels), read by field name (each a column, one value per substep)."""

    f: np.ndarray
    i: np.ndarray

    max_speed = _float_field(DIAG_MAX_SPEED, "m/s")
    max_acceleration = _float_field(DIAG_MAX_ACCEL, "m/s^2 (DFSPH: of the non-pressure forces)")
    max_density_error = _float_field(DIAG_MAX_DENSITY_ERROR, "max |rho - rho0| / rho0")
    max_compression = _float_field(DIAG_MAX_COMPRESSION, "max (rho - rho0) / rho0")
    kinetic_energy = _float_field(DIAG_KINETIC_ENERGY, "J")
    potential_energy = _float_field(DIAG_POTENTIAL_ENERGY, "J")
    removed_energy = _float_field(DIAG_REMOVED_ENERGY, "J")
    internal_energy = _float_field(DIAG_INTERNAL_ENERGY, "J")
    divergence_error = _float_field(DIAG_DIVERGENCE_ERROR, "relative error the divergence solve left (DFSPH)")
    density_solve_error = _float_field(DIAG_DENSITY_SOLVE_ERROR, "relative error the density solve left (DFSPH)")
    nonfinite = _int_field(DIAG_NONFINITE, "particles")
    wall_breaches = _int_field(DIAG_BREACHES, "particles")
    wall_corrections = _int_field(DIAG_CORRECTIONS, "particles")
    active = _int_field(DIAG_ACTIVE, "particles")
    divergence_iterations = _int_field(DIAG_DIVERGENCE_ITERATIONS, "iterations (DFSPH)")
    density_iterations = _int_field(DIAG_DENSITY_ITERATIONS, "iterations (DFSPH)")
    pair_overflows = _int_field(DIAG_PAIR_OVERFLOW, "particles")

    @property
    def inside(self) -> np.ndarray:
        """(substeps, vessels): particles inside each vessel."""
        return self.i[:, N_DIAG_INT_BASE:]

    def __len__(self) -> int:
        return self.f.shape[0]

    @staticmethod
    def concatenate(parts: "list[SubstepRows]") -> "SubstepRows":
        return SubstepRows(np.concatenate([p.f for p in parts]), np.concatenate([p.i for p in parts]))

    def record(self, s: int, step: int, time: float, dt: float, n_total: int, particle_volume: float) -> StepDiagnostics:
        """Substep ``s`` of these rows as a host record (``step``: its number, ``time``: s at its end)."""
        return StepDiagnostics(
            step=step,
            time=time,
            dt=dt,
            max_speed=float(self.max_speed[s]),
            max_acceleration=float(self.max_acceleration[s]),
            max_density_error=float(self.max_density_error[s]),
            max_compression=float(self.max_compression[s]),
            kinetic_energy=float(self.kinetic_energy[s]),
            nonfinite=int(self.nonfinite[s]),
            wall_breaches=int(self.wall_breaches[s]),
            wall_corrections=int(self.wall_corrections[s]),
            active=int(self.active[s]),
            solver_iterations=(int(self.divergence_iterations[s]), int(self.density_iterations[s])),
            volume_in_vessel=tuple(float(c) * particle_volume for c in self.inside[s]),
            spilled_volume=(n_total - int(self.active[s])) * particle_volume,
        )


class DiagnosticBuffers:
    """Each lane's device rows of the substeps' diagnostics: ``f`` (lanes, rows x replicas, N_DIAG_FLOAT) and ``i``
    (lanes, rows x replicas, N_DIAG_INT_BASE + vessels), room for :attr:`capacity` substeps; the particle kernels
    write their lane's rows (:attr:`lane_f`, :attr:`lane_i`)."""

    def __init__(self, lanes: int, replicas: int, n_vessels: int, device, substeps: int = 64):
        self.lanes, self.replicas, self.n_vessels, self.device = lanes, replicas, n_vessels, device
        self.capacity = 0
        self.ensure(substeps)

    def ensure(self, substeps: int) -> bool:
        """Room for ``substeps`` rows; True when the arrays were replaced (at least doubled), which programs that
        hold the old ones must be recorded again for."""
        if substeps <= self.capacity:
            return False
        self.capacity = max(substeps, 2 * self.capacity)
        slots = self.capacity * self.replicas
        self.f = wp.zeros((self.lanes, slots, N_DIAG_FLOAT), dtype=float, device=self.device)
        self.i = wp.zeros((self.lanes, slots, N_DIAG_INT_BASE + self.n_vessels), dtype=wp.int32, device=self.device)
        self.lane_f = PerLane(self.f[k] for k in range(self.lanes))
        self.lane_i = PerLane(self.i[k] for k in range(self.lanes))
        self._views = (self.f.numpy(), self.i.numpy()) if self.device.is_cpu else None  # shared memory
        return True

    def zero(self) -> None:
        if self._views is not None:  # the CPU's arrays through their numpy views: no warp call per interval
            for view in self._views:
                view.fill(0)
            return
        self.f.zero_()
        self.i.zero_()

    def read(self, substeps: int) -> SubstepRows:
        """The first ``substeps`` rows, the lanes and replicas combined (from the device's copy only the rows
        written)."""
        used = substeps * self.replicas
        diag_f, diag_i = self._views or (read_lane_rows(self.f, used), read_lane_rows(self.i, used))
        return SubstepRows(*combine_lanes(replicas_as_lanes(diag_f, substeps, self.replicas), replicas_as_lanes(diag_i, substeps, self.replicas)))
