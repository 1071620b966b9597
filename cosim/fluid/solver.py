"""The SPH liquid solver: the public object of ``cosim.fluid``.

Time is advanced in intervals (the coupling's MuJoCo step, or any duration): before an interval the caller gives
each vessel's pose at the END of the interval (:meth:`FluidSolver.set_vessel_poses`); the vessel then moves from
its current pose to that one at constant linear and angular velocity while the liquid takes as many equal
substeps as the CFL, force and viscous criteria need (computed from the previous interval's maxima and the wall
speed). Each substep runs the named stages of the configured pressure solver, WCSPH (``cosim.fluid.wcsph``)

    move_vessels; place_wall_particles; find_neighbors; update_free_liquid; extrapolate_wall_state;
    compute_forces; compute_density_rate; integrate (+ wall guard); reduce_wrenches

or DFSPH (``cosim.fluid.dfsph``)

    move_vessels; place_wall_particles; find_neighbors; compute_density_factor; divergence solve;
    compute_nonpressure; density solve; compute_wall_reaction; integrate (+ wall guard); reduce_wrenches

entirely on the device (no host copies inside; only the interval's plan and its diagnostics cross; DFSPH's
convergence loops read a device flag through ``wp.capture_while``, see ``cosim.fluid.dfsph``). From the second
interval on each substep is replayed as one captured graph: a CUDA graph on a CUDA device (the same results to the
bit as the launches, ``python -m cosim.bench.device_check``), on the CPU warp's operation stream
(APIC), which replays the launches in C++ without Python's per-launch argument handling (same results to the bit,
tests/test_fluid_graphs.py). On the CPU the particle kernels are split over threads, each replaying its own graph of
its share of the particles with barriers between the stages (``cosim.fluid.lanes``, ``cpu_threads``; same results to
the bit, tests/test_fluid_lanes.py). After the interval the per-substep diagnostics are checked and an instability
raises :class:`FluidInstabilityError` naming the step and what broke. Results come back as numpy arrays in the
particles' original order.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Sequence

import numpy as np
import warp as wp

from cosim.errors import InputError, SimulationError, count_of
from cosim.fluid import boundary as bd
from cosim.fluid import dfsph, wcsph
from cosim.fluid.config import DensityIteration, FluidConfig, PressureSolver
from cosim.fluid.device_layout import DeviceLayout, layout_for, pair_table, reduction_levels
from cosim.fluid.sph_common import accumulate_wall_wrench, gather_particles, next_substep, pair_capacity, sum_wall_wrench_chunks
from cosim.fluid.diagnostics import (
    DIAG_INTERNAL_ENERGY, DIAG_KINETIC_ENERGY, DIAG_POTENTIAL_ENERGY, DIAG_REMOVED_ENERGY, N_DIAG_FLOAT, N_DIAG_INT_BASE, StepDiagnostics, combine_lanes, read_lane_rows,
    replicas_as_lanes, rows_to_records,
)
from cosim.fluid.energy import EnergyAccount
from cosim.fluid.lanes import LANE_CHUNK, Lanes, Loop, PerLane, Stage, lane_count, run_serial, together
from cosim.fluid.memory import allocation_failure_refused
from cosim.fluid.model import FluidModel, FluidState, build_model
from cosim.fluid.runtime import resolve_device
from cosim.fluid.seeding import ParticleSet
from cosim.frames import Pose, rotation_vector, rotation_y, tilt_about_y, vector_norm
from cosim.vessel import VesselSpec

FORCE_CFL = 0.25  # Monaghan's force criterion dt <= 0.25 sqrt(h / a_max)
VISCOUS_CFL = 0.125  # viscous criterion dt <= 0.125 h^2 / nu
GUARD_MARGIN = 0.01  # the guard puts a particle this many dx outside the wall face it crossed


class FluidInstabilityError(SimulationError):
    """The liquid broke: non-finite values, density error past its bound, a wall breached, a collapsed step."""

    def __init__(self, step: int, time: float, reason: str):
        super().__init__(f"SPH step {step} (t = {time:.5f} s): {reason}")
        self.step = step
        self.time = time
        self.reason = reason


# diagnostics columns whose non-zero count stops the run (``_check``): non-finite, wall breaches, pair overflow
_CHECKED_COUNTS = [0, 1, 6]


@dataclass(frozen=True)
class IntervalReport:
    """What one :meth:`FluidSolver.advance` did: substeps taken, their dt (s), and the last substep's record
    (:attr:`last`, built from ``_record`` when first asked for: most intervals never are)."""

    substeps: int
    dt: float
    _record: Callable[[], StepDiagnostics] = field(repr=False)

    @cached_property
    def last(self) -> StepDiagnostics:
        return self._record()


class FluidSolver:
    """SPH liquid in moving rigid vessels.

    Args:
      config: :class:`FluidConfig`.
      vessels: vessel specifications (their frames as in ``cosim.vessel``).
      poses: initial world pose of each vessel frame.
      particles: the initial liquid (e.g. from :func:`cosim.fluid.seeding.fill_vessel`).
      device: "cpu" or "cuda[:N]".
      graphs: replay each substep as one captured graph (CUDA graph, or on the CPU warp's APIC operation stream;
        captured after the first interval, which runs the operations one by one and so compiles the kernels and
        sizes the sort's scratch memory); the operations one by one where capture fails
        (:attr:`graph_capture_error` says why) or when False.
      layout: how the pair tables, the wrench reduction and the atomic accumulators are laid out
        (:mod:`cosim.fluid.device_layout`); None: the device kind's own. The particles are the same under any.
    In 2-D, vessel poses are projected onto the pour plane (rotation about y, translation in x-z, y = 0).
    """

    def __init__(
        self,
        config: FluidConfig,
        vessels: Sequence[VesselSpec],
        poses: Sequence[Pose],
        particles: ParticleSet,
        device: str = "cpu",
        graphs: bool = True,
        layout: DeviceLayout | None = None,
    ):
        if len(vessels) != len(poses):
            raise InputError(f"fluid: {len(vessels)} vessels but {len(poses)} poses")
        if len(particles) == 0:
            raise InputError("fluid: the initial liquid holds no particle")
        if config.dim == 2 and not (config.domain_min[1] < 0.0 < config.domain_max[1]):
            raise InputError("fluid.domain_min[1]..domain_max[1]: must contain y = 0 (the pour plane) in 2-D")
        self.config = config
        self.device = resolve_device(device)
        sweeps = config.pressure_solver is PressureSolver.DFSPH and config.density_iteration is DensityIteration.GAUSS_SEIDEL
        self.layout = layout or layout_for(self.device, sweeps)
        self.n_particles = len(particles)
        self.lanes = Lanes(lane_count(config.cpu_threads, self.n_particles, self.device), self.device)
        self.time = 0.0
        self.step_count = 0
        self.substep_wall_time = 0.0  # s of wall clock spent in the substeps (device work included), for benchmarks
        self._poses = [self._planar(p) for p in poses]
        self._targets = list(self._poses)
        self._last_max_speed = 0.0
        self._last_max_accel = config.gravity_magnitude
        self._history: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self._last_report: IntervalReport | None = None
        self._capture_graphs = graphs
        self.graph_capture_error: str | None = None
        self._graphs: tuple | None = None  # per lane: (even, odd) substep graphs
        # a profiler's hook (cosim.bench.kernel_profile): runs each operation of substeps launched one by one
        # (graphs=False), ``operation_hook(op)`` calling ``op()``; None: the operations are called directly
        self.operation_hook: Callable[[Callable[[], None]], None] | None = None
        with allocation_failure_refused(self.device):
            self.model: FluidModel = build_model(config, tuple(vessels), self.n_particles, self.device, self.layout.atomic_replicas)
            self._allocate(particles)
        self.energy_account = EnergyAccount(config, vessels, particles.positions, particles.velocities, self._internal_energy())

    # ---- set-up ----------------------------------------------------------------------------------------------
    def _planar(self, pose: Pose) -> Pose:
        if self.config.dim == 3:
            return Pose(pose.position, pose.rotation)
        pos = pose.position.copy()
        pos[1] = 0.0
        return Pose(pos, rotation_y(tilt_about_y(pose.rotation)))

    def _allocate(self, particles: ParticleSet) -> None:
        d, n, m = self.device, self.n_particles, self.model
        v_count = max(m.n_vessels, 1)
        self.state = FluidState.allocate(n, d)
        self._spare = FluidState.allocate(n, d)
        self.state.x.assign(particles.positions.astype(np.float32))
        self.state.v.assign(particles.velocities.astype(np.float32))
        self.state.rho.assign(particles.densities.astype(np.float32))
        self.state.active.fill_(1)
        self.state.mass.fill_(self.config.particle_mass)
        self.state.pid.assign(np.arange(n, dtype=np.int32))
        wp.launch(wcsph.equation_of_state, dim=n, inputs=[m.params, self.state.rho], outputs=[self.state.p], device=d)
        if self.config.pressure_solver is PressureSolver.DFSPH:
            # the seeded pressure (hydrostatic for a filled vessel) as the stiffness the liquid was already under:
            # the first density solve warm-starts from it as from any previous substep's
            self.state.kappa_density.assign((self.state.p.numpy() / self.state.rho.numpy()).astype(np.float32))
            self.state.rest_offset.fill_(float(dfsph.UNSEEDED_OFFSET))
        self._drho = wp.zeros(n, dtype=float, device=d)
        self._acc = wp.zeros(n, dtype=wp.vec3, device=d)
        self._rho_grad = wp.zeros(n, dtype=wp.vec3, device=d)
        self._v_star = wp.zeros(n, dtype=wp.vec3, device=d)
        self._alpha = wp.zeros(n, dtype=float, device=d)
        self._increment = wp.zeros(n, dtype=float, device=d)
        self._increment_per_rho = wp.zeros(n, dtype=float, device=d)
        replicas = self.layout.atomic_replicas  # rows per lane (check_convergence sums every row)
        self._solve_stats = wp.zeros((self.lanes.count * replicas, dfsph.STATS_ROW_STRIDE), dtype=wp.int64, device=d)
        self._lane_stats = PerLane(self._solve_stats[k * replicas : (k + 1) * replicas].flatten() for k in range(self.lanes.count))
        capacity = pair_capacity(self.config.dim, self.model.densest_smoothing_ratio)
        self._pair_count = wp.zeros(n, dtype=wp.int32, device=d)
        by_column = self.layout.pairs_by_column
        self._pair_index = pair_table(n, capacity, wp.int32, d, by_column)
        self._pair_grad = pair_table(n, capacity, wp.vec3, d, by_column)
        dfsph_only = self.config.pressure_solver is PressureSolver.DFSPH
        self._pair_mass_grad = pair_table(n, capacity, wp.vec3, d, by_column) if dfsph_only else None
        self._keep_going = wp.zeros(1, dtype=wp.int32, device=d)
        self._wall_force = wp.zeros((v_count, n), dtype=wp.vec3, device=d)
        self._wall_torque = wp.zeros((v_count, n), dtype=wp.vec3, device=d)
        self._wrench_levels = reduction_levels(n, self.layout.interleaved_reduction)
        self._partial_wrench = [
            (wp.zeros((v_count, level.chunks), dtype=wp.vec3, device=d), wp.zeros((v_count, level.chunks), dtype=wp.vec3, device=d))
            for level in self._wrench_levels
        ]
        self._force_sum = wp.zeros(v_count, dtype=wp.vec3, device=d)
        self._torque_sum = wp.zeros(v_count, dtype=wp.vec3, device=d)
        self._wrench_views = (self._force_sum.numpy(), self._torque_sum.numpy()) if d.is_cpu else None  # shared memory
        nb = m.n_boundary
        self._bx = wp.zeros(nb, dtype=wp.vec3, device=d)
        self._bv = wp.zeros(nb, dtype=wp.vec3, device=d)
        self._b_p = wp.zeros(nb, dtype=float, device=d)
        self._b_rho = wp.zeros(nb, dtype=float, device=d)
        self._b_v_noslip = wp.zeros(nb, dtype=wp.vec3, device=d)
        if self.config.pressure_solver is PressureSolver.DFSPH:
            self._b_alpha = wp.zeros(nb, dtype=float, device=d)
            self._b_increment = wp.zeros(nb, dtype=float, device=d)
            self._b_increment_per_rho = wp.zeros(nb, dtype=float, device=d)
            self._b_kappa_density = wp.zeros(nb, dtype=float, device=d)
            self._b_kappa_divergence = wp.zeros(nb, dtype=float, device=d)
            self._b_pair_count = wp.zeros(nb, dtype=wp.int32, device=d)
            self._b_pair_index = pair_table(nb, capacity, wp.int32, d, by_column)
            self._b_pair_mass_grad = pair_table(nb, capacity, wp.vec3, d, by_column)
            if self.config.density_iteration is DensityIteration.GAUSS_SEIDEL:  # dfsph.list_sweep_cells
                threads = self._sweep_threads()
                per_thread = -(-(n + nb) // threads)
                self._sweep_count = wp.zeros(threads, dtype=wp.int32, device=d)
                self._sweep_cell = wp.zeros((threads, per_thread), dtype=wp.int32, device=d)
                self._sweep_color = wp.zeros((threads, per_thread), dtype=wp.int32, device=d)
        self._b_active = wp.ones(nb, dtype=wp.int32, device=d)
        self._motions = wp.zeros(m.n_vessels, dtype=bd.VesselMotion, device=d)
        # the motions are written on the host through a structured numpy view (the CPU device's array itself, else a
        # pinned staging copy): no per-field warp struct assignment in the step loop
        self._motions_host = self._motions if not d.is_cuda else wp.zeros(m.n_vessels, dtype=bd.VesselMotion, device="cpu", pinned=True)
        self._motions_view = self._motions_host.numpy()
        self._dt = wp.zeros(1, dtype=float, device=d)
        self._substep_weight = wp.zeros(1, dtype=float, device=d)
        self._dt_written = self._weight_written = None  # the values last written to _dt and _substep_weight
        self._row = wp.zeros(1, dtype=wp.int32, device=d)
        self._rows_capacity = 0
        self._ensure_rows(64)
        self._parity = 0
        zero = np.zeros((m.n_vessels, 3))
        self._lin_vel, self._ang_vel = zero, zero
        self._upload_motions(zero, zero, zero, zero)
        self._wrench = np.zeros((m.n_vessels, 6))

    def _internal_energy(self) -> float:
        """Elastic energy the liquid stores (J): WCSPH's Tait liquid; DFSPH's incompressible one stores none."""
        if self.config.pressure_solver is not PressureSolver.WCSPH:
            return 0.0
        energy = wp.zeros(self.n_particles, dtype=float, device=self.device)
        wp.launch(wcsph.measure_internal_energy, dim=self.n_particles, inputs=[self.model.params, self.state.rho], outputs=[energy], device=self.device)
        return float(energy.numpy().astype(np.float64).sum())

    def _ensure_rows(self, n: int) -> None:
        """Room for ``n`` substeps of diagnostics (the recorded operations are rebuilt when the rows grow)."""
        if n <= self._rows_capacity:
            return
        self._rows_capacity = max(n, 2 * self._rows_capacity)
        lanes, slots = self.lanes.count, self._rows_capacity * self.layout.atomic_replicas
        self._diag_f = wp.zeros((lanes, slots, N_DIAG_FLOAT), dtype=float, device=self.device)
        self._diag_i = wp.zeros((lanes, slots, N_DIAG_INT_BASE + self.model.n_vessels), dtype=wp.int32, device=self.device)
        self._lane_diag_f = PerLane(self._diag_f[k] for k in range(lanes))
        self._lane_diag_i = PerLane(self._diag_i[k] for k in range(lanes))
        self._diag_views = (self._diag_f.numpy(), self._diag_i.numpy()) if self.device.is_cpu else None  # shared memory
        self._ops = None
        self._graphs = None

    def _upload_motions(self, lin_vel: np.ndarray, ang_vel: np.ndarray, lin_acc: np.ndarray, ang_acc: np.ndarray) -> None:
        """The vessels' motion over the next interval (world frame; (V, 3) m/s, rad/s, m/s^2, rad/s^2), from their
        current poses; the substeps' own poses start there."""
        if not self._poses:
            return
        mo = self._motions_view
        mo["p0"] = mo["p_now"] = mo["p_next"] = [pose.position for pose in self._poses]
        mo["r0"] = mo["r_now"] = mo["r_next"] = [pose.rotation for pose in self._poses]
        mo["lin_vel"], mo["ang_vel"], mo["lin_acc"], mo["ang_acc"] = lin_vel, ang_vel, lin_acc, ang_acc
        if self._motions_host is not self._motions:  # copied into the existing array: the recorded launches hold it
            wp.copy(self._motions, self._motions_host)

    # ---- driving ---------------------------------------------------------------------------------------------
    def set_vessel_poses(self, poses: Sequence[Pose]) -> None:
        """World poses of the vessel frames at the end of the next :meth:`advance` interval."""
        if len(poses) != self.model.n_vessels:
            raise InputError(f"fluid: {self.model.n_vessels} vessels but {len(poses)} poses given")
        for k, pose in enumerate(poses):
            if not (math.isfinite(pose.position.sum()) and math.isfinite(pose.rotation.sum())) and not (
                np.all(np.isfinite(pose.position)) and np.all(np.isfinite(pose.rotation))
            ):  # a finite sum is the cheap proof (a NaN or inf propagates); an overflowing one is looked at closely
                raise InputError(f"fluid: vessel {self.model.vessel_specs[k].name} pose is not finite")
        self._targets = [self._planar(p) for p in poses]

    def plan_time_step(self, duration: float, wall_speed: float) -> tuple[int, float]:
        """(substeps, dt) for an interval: CFL with the wall speed (acoustic for WCSPH, on the flow speed alone for
        DFSPH), force and viscous criteria; with ``adaptive_time_step`` off, the fixed step of the expected speed
        (and the viscous criterion)."""
        cfg = self.config
        h = cfg.smoothing_length
        sound = cfg.sound_speed if cfg.pressure_solver is PressureSolver.WCSPH else 0.0
        if not cfg.adaptive_time_step:
            dt = cfg.fixed_time_step
        else:
            if cfg.pressure_solver is PressureSolver.WCSPH:
                signal = sound + self._last_max_speed + wall_speed
            else:  # the expected speed bounds the step before the flow has reached it (a jet forms within an interval)
                signal = max(cfg.max_expected_speed, self._last_max_speed) + wall_speed
            dt = cfg.cfl * h / max(signal, 1e-9)
            dt = min(dt, FORCE_CFL * math.sqrt(h / max(self._last_max_accel, 1e-9)))
        if cfg.kinematic_viscosity > 0.0:
            dt = min(dt, VISCOUS_CFL * h * h / cfg.kinematic_viscosity)
        if dt < cfg.min_time_step:
            raise FluidInstabilityError(self.step_count, self.time, f"time step collapsed to {dt:.3g} s (< fluid.min_time_step)")
        n = max(1, math.ceil(duration / dt - 1e-9))
        return n, duration / n

    def advance(self, duration: float) -> IntervalReport:
        """Advance the liquid by ``duration`` (s), moving each vessel to its target pose meanwhile."""
        if not (duration > 0.0 and math.isfinite(duration)):
            raise InputError(f"fluid.advance: duration must be > 0 s, got {duration}")
        m = self.model
        lin = np.array([(t.position - p.position) / duration for p, t in zip(self._poses, self._targets)]).reshape(-1, 3)
        ang = np.array([rotation_vector(t.rotation @ p.rotation.T) / duration for p, t in zip(self._poses, self._targets)]).reshape(-1, 3)
        wall_speed = max((vector_norm(lin[k]) + vector_norm(ang[k]) * m.b_reach[k] for k in range(m.n_vessels)), default=0.0)
        n_sub, dt = self.plan_time_step(duration, wall_speed)
        self._upload_motions(lin, ang, (lin - self._lin_vel) / duration, (ang - self._ang_vel) / duration)
        self._lin_vel, self._ang_vel = lin, ang
        self._ensure_rows(n_sub)
        if self._ops is None:
            even, odd = (self.state, self._spare) if self._parity == 0 else (self._spare, self.state)
            self._ops = (self._substep_commands(even, odd), self._substep_commands(odd, even))
        if dt != self._dt_written:  # the substeps read it on the device; most intervals keep the last one
            self._dt.fill_(dt)
            self._dt_written = dt
        if self.config.pressure_solver is PressureSolver.DFSPH:  # its pressure is averaged over the interval
            if n_sub != self._weight_written:
                self._substep_weight.fill_(1.0 / n_sub)
                self._weight_written = n_sub
            self.state.p.zero_()
        self._row.zero_()
        self._diag_f.zero_()
        self._diag_i.zero_()
        self._force_sum.zero_()
        self._torque_sum.zero_()
        start = time.perf_counter()
        self._run_substeps(n_sub)
        if self.device.is_cuda:
            wp.synchronize_device(self.device)  # the diagnostics copy below waits for the device anyway
        self.substep_wall_time += time.perf_counter() - start
        if self._capture_graphs and self._graphs is None:
            self._graphs = self._capture()
        used = n_sub * self.layout.atomic_replicas  # rows written this interval (the device's copy: read only those)
        diag_f, diag_i = self._diag_views or (read_lane_rows(self._diag_f, used), read_lane_rows(self._diag_i, used))
        rows_f, rows_i = combine_lanes(*(replicas_as_lanes(a, n_sub, self.layout.atomic_replicas) for a in (diag_f, diag_i)))
        first = self.step_count
        t0 = self.time
        self.step_count += n_sub
        self.time += duration
        self._history.append((np.full(n_sub, dt), rows_f, rows_i))
        scale = 1.0 / n_sub
        wrench = np.concatenate(self._wrench_views or (self._force_sum.numpy(), self._torque_sum.numpy()), axis=1)[: m.n_vessels]
        self._wrench = wrench.astype(np.float64) * scale
        self.energy_account.update(
            float(rows_f[-1, DIAG_KINETIC_ENERGY] + rows_f[-1, DIAG_INTERNAL_ENERGY]), float(rows_f[-1, DIAG_POTENTIAL_ENERGY]), float(rows_f[:, DIAG_REMOVED_ENERGY].sum()),
            self._wrench, self._poses, lin, ang, duration,
        )
        self._poses = list(self._targets)
        self._check(first, t0, dt, rows_f, rows_i)
        self._last_max_speed = float(rows_f[:, 0].max())
        self._last_max_accel = float(rows_f[:, 1].max())
        n, volume = self.n_particles, self.config.particle_volume
        self._last_report = IntervalReport(
            n_sub, dt, lambda: rows_to_records(first + n_sub - 1, t0 + (n_sub - 1) * dt, dt, rows_f[-1:], rows_i[-1:], n, volume)[0],
        )
        return self._last_report

    def _substep_commands(self, src: FluidState, dst: FluidState) -> list[Stage | Loop]:
        """The substep as stages of operations with bound arguments (recorded launches: no per-call argument
        packing), for the particle state ``src``, which is reordered into ``dst`` and advanced there; the particle
        kernels split over the lanes (``cosim.fluid.lanes``).

        Stages: move_vessels; place_wall_particles; find_neighbors (wall particles by indirection on lane 0, liquid
        reordered into cell order on the last lane); the pressure solver's stages; reduce_wrenches (fixed order);
        next_substep."""
        m, n, nb, nv = self.model, self.n_particles, self.model.n_boundary, self.model.n_vessels
        lanes = self.lanes
        stages = []
        if nv:
            stages.append(lanes.on_lane(0, self._rec(bd.advance_vessel_poses, nv, [self._row, self._dt], [self._motions])))
            stages.append(lanes.launch(bd.place_wall_particles, nb, [m.b_local, m.b_vessel, self._motions], [self._bx, self._bv]))
        stages.append(together(
            lanes.on_lane(0, *m.b_grid.build_commands(self._bx, self._b_active, nb)), lanes.on_lane(-1, *m.grid.build_commands(src.x, src.active, n)),
        ))
        stages.append(lanes.launch(gather_particles, n, [m.grid.order, *src.arrays()], dst.arrays()))
        if self.config.pressure_solver is PressureSolver.DFSPH:
            stages += self._dfsph_commands(dst)
        else:
            stages += self._wcsph_commands(dst)
        tail = []
        if nv:
            source, length = (self._wall_force, self._wall_torque), n
            for level, partial in zip(self._wrench_levels, self._partial_wrench):
                bounds = [level.length, level.first_stride, level.item_stride, level.items]
                tail.append(self._rec(sum_wall_wrench_chunks, (nv, level.chunks), [*bounds, *source], partial))
                source, length = partial, level.chunks
            tail.append(self._rec(accumulate_wall_wrench, nv, [length, *source], [self._force_sum, self._torque_sum]))
        tail.append(self._rec(next_substep, 1, [self._row]))
        stages.append(lanes.on_lane(0, *tail))
        return stages

    def _rec(self, kernel, dim, inputs, outputs=()):
        """A launch recorded with its arguments bound (call ``.launch()`` to run it)."""
        return wp.launch(kernel, dim=dim, inputs=inputs, outputs=list(outputs), device=self.device, record_cmd=True).launch

    def _integrate_model_args(self) -> list:
        cfg = self.config
        return [
            self.model.params, self.model.vessels, wp.vec3(*cfg.domain_min), wp.vec3(*cfg.domain_max), GUARD_MARGIN * cfg.spacing,
            cfg.max_wall_penetration * cfg.spacing, self._motions, self._dt, self._row,
        ]

    def _wcsph_commands(self, st: FluidState) -> list[Stage]:
        """update_free_liquid (if ``free_liquid``); extrapolate_wall_state; compute_forces; compute_density_rate;
        integrate (``cosim.fluid.wcsph``)."""
        m, prm, n, nb = self.model, self.model.params, self.n_particles, self.model.n_boundary
        launch = self.lanes.launch
        pairs = [self._pair_count, self._pair_index, self._pair_grad]
        diag = [self._lane_diag_f, self._lane_diag_i]
        stages = []
        if self.config.free_liquid:
            stages.append(launch(
                wcsph.update_free_liquid, n,
                [prm, m.grid.spec, m.vessels, m.b_volume, self._motions, st.x, st.active, st.mass, m.grid.cell_start, m.grid.cell_end,
                 self._bx, m.b_grid.order, m.b_grid.cell_start, m.b_grid.cell_end],
                [st.free, st.rho, st.p],
            ))
        if nb:
            stages.append(launch(
                bd.extrapolate_wall_state, nb,
                [prm, m.grid.spec, m.b_vessel, self._motions, self._bx, self._bv, st.x, st.v, st.rho, st.p, m.grid.cell_start, m.grid.cell_end],
                [self._b_p, self._b_rho, self._b_v_noslip],
            ))
        stages.append(launch(
            wcsph.compute_forces, n,
            [
                prm, m.grid.spec, m.vessels, m.b_volume, m.b_vessel,
                self._motions, st.x, st.v, st.rho, st.p, st.active, st.free, st.mass, m.grid.cell_start, m.grid.cell_end,
                self._bx, self._bv, self._b_p, self._b_rho, self._b_v_noslip,
                m.b_grid.order, m.b_grid.cell_start, m.b_grid.cell_end, self._row, self._pair_index.shape[1],
            ],
            [self._acc, self._rho_grad, self._wall_force, self._wall_torque, *pairs, *diag],
        ))
        stages.append(launch(
            wcsph.compute_density_rate, n,
            [prm, m.b_volume, st.x, st.v, self._acc, st.rho, self._rho_grad, st.active, st.mass, self._dt, self._bv, *pairs],
            [self._drho],
        ))
        stages.append(launch(
            wcsph.integrate, n, [*self._integrate_model_args(), self._drho, self._acc, st.free, st.mass],
            [st.x, st.v, st.rho, st.p, st.active, self._wall_force, self._wall_torque, *diag],
        ))
        return stages

    def _dfsph_commands(self, st: FluidState) -> list[Stage | Loop]:
        """compute_density_factor; divergence solve; compute_nonpressure; density solve; compute_wall_reaction;
        integrate (``cosim.fluid.dfsph``). Each solve is a ``wp.capture_while`` loop on a device flag."""
        m, prm, n, nb = self.model, self.model.params, self.n_particles, self.model.n_boundary
        launch = self.lanes.launch
        grid = [m.grid.cell_start, m.grid.cell_end]
        walls = [self._bx, m.b_grid.order, m.b_grid.cell_start, m.b_grid.cell_end]
        pairs = [self._pair_count, self._pair_index, self._pair_grad]
        _, b_pairs = self._solve_pairs()
        increments = [self._increment, self._increment_per_rho]
        stats, diag_f, diag_i = self._lane_stats, self._lane_diag_f, self._lane_diag_i
        gauss_seidel = self.config.density_iteration is DensityIteration.GAUSS_SEIDEL

        return [
            launch(
                dfsph.compute_density_factor, n,
                [
                    prm, m.grid.spec, m.vessels, m.b_volume, self._pair_index.shape[1], int(self.config.free_liquid), self._motions, st.x, st.active, st.mass,
                    *grid, *walls, self._row, st.kappa_divergence, st.free, st.rest_offset,
                ],
                [st.rho, self._alpha, *increments, *pairs, self._pair_mass_grad, stats, self._keep_going, diag_f, diag_i],
            ),
            together(
                launch(
                    dfsph.compute_wall_density_factor, nb,
                    [prm, m.grid.spec, m.b_volume, m.b_wetted, self._b_pair_index.shape[1], st.x, st.mass, *grid, *walls, self._row],
                    [self._b_rho, self._b_alpha, *b_pairs, stats, diag_i],
                ),
                launch(
                    dfsph.start_wall_solve, nb, [float(dfsph.WARM_START_DIVERGENCE), 0, self._b_rho],
                    [self._b_kappa_divergence, self._b_increment, self._b_increment_per_rho],
                ),
            ),
            self._jacobi_solve(st, dfsph.SOLVE_DIVERGENCE, st.v, st.kappa_divergence, self._b_kappa_divergence),
            together(
                launch(
                    dfsph.compute_nonpressure, n, [prm, m.b_volume, st.x, st.v, st.rho, st.active, self._dt, self._bx, self._bv, *pairs, self._row, st.free, st.mass, st.kappa_density],
                    [self._v_star, *increments, stats, self._keep_going, diag_f],
                ),
                launch(
                    dfsph.start_wall_solve, nb, [float(dfsph.WARM_START_DENSITY), int(gauss_seidel), self._b_rho],
                    [self._b_kappa_density, self._b_increment, self._b_increment_per_rho],
                ),
                *([self._list_sweep_cells()] if gauss_seidel else []),
            ),
            *(self._gauss_seidel_density_solve(st) if gauss_seidel else [self._jacobi_solve(st, dfsph.SOLVE_DENSITY, self._v_star, st.kappa_density, self._b_kappa_density)]),
            launch(
                dfsph.compute_wall_reaction, n,
                [
                    prm, m.vessels, m.b_volume, m.b_vessel, self._motions, st.x, st.v, st.rho, st.kappa_density,
                    st.kappa_divergence, st.active, self._bx, self._bv, *pairs, self._b_rho, self._b_kappa_density, self._b_kappa_divergence,
                    self._substep_weight, st.free,
                ],
                [self._wall_force, self._wall_torque, st.p],
            ),
            launch(dfsph.integrate, n, [*self._integrate_model_args(), self._v_star, st.rho], [st.x, st.v, st.active, st.mass, st.free, self._wall_force, self._wall_torque, diag_f, diag_i]),
            self.lanes.on_lane(0, self._solve_stats.zero_),
        ]

    def _solve_pairs(self) -> tuple[list, list]:
        """The pair lists the DFSPH solves loop over, as kernel arguments: the liquid's (count, index, mass-weighted
        kernel gradient) and the wall layer's."""
        return (
            [self._pair_count, self._pair_index, self._pair_mass_grad],
            [self._b_pair_count, self._b_pair_index, self._b_pair_mass_grad],
        )

    def _apply_stiffness(self, st: FluidState, v: wp.array, kappa: wp.array) -> Stage:
        """The stage that applies the pending stiffness increments (a solve's warm start, or a Jacobi iteration's)."""
        pairs, _ = self._solve_pairs()
        return self.lanes.launch(
            dfsph.apply_stiffness, self.n_particles, [self._increment, self._increment_per_rho, st.active, self._dt, *pairs, self._b_increment_per_rho], [v, kappa],
        )

    def _convergence_check(self, mode: int) -> Stage:
        """The stage that ends a solve's iteration: its error measured, the stop decided (``check_convergence``)."""
        check = self._rec(
            dfsph.check_convergence, 1, [self.model.params, mode, self._row], [self._solve_stats, self._keep_going, self._lane_diag_f[0], self._lane_diag_i[0]],
        )
        return self.lanes.on_lane(0, check)

    def _jacobi_solve(self, st: FluidState, mode: int, v: wp.array, kappa: wp.array, b_kappa: wp.array) -> Loop:
        """A solve by Jacobi iterations (``mode``: dfsph.SOLVE_DIVERGENCE or SOLVE_DENSITY): each applies the
        increments the last measured (the first, the warm start), then measures the liquid's and the wall layer's
        errors and their next increments."""
        prm, n, nb = self.model.params, self.n_particles, self.model.n_boundary
        launch = self.lanes.launch
        pairs, b_pairs = self._solve_pairs()
        increments = [self._increment, self._increment_per_rho]
        return Loop(self._keep_going, (
            self._apply_stiffness(st, v, kappa),
            together(
                launch(dfsph.compute_solve_error, n, [prm, mode, v, st.rho, self._alpha, st.active, self._dt, self._bv, *pairs], [*increments, self._lane_stats]),
                launch(
                    dfsph.compute_wall_solve_error, nb, [prm, mode, v, self._dt, self._bv, self._b_rho, self._b_alpha, *b_pairs],
                    [b_kappa, self._b_increment, self._b_increment_per_rho, self._lane_stats],
                ),
            ),
            self._convergence_check(mode),
        ))

    def _sweep_threads(self) -> int:
        """Threads of each Gauss-Seidel colour launch (``cosim.fluid.dfsph.gauss_seidel_density_sweep``): one per
        item on CUDA, a chunk per lane on the CPU."""
        return self.n_particles + self.model.n_boundary if self.device.is_cuda else LANE_CHUNK * self.lanes.count

    def _list_sweep_cells(self) -> Stage:
        """The launch that lists each sweep thread's cells for the substep (``cosim.fluid.dfsph.list_sweep_cells``)."""
        m, n, threads = self.model, self.n_particles, self._sweep_threads()
        return self.lanes.launch(
            dfsph.list_sweep_cells, threads, [m.grid.spec, n, n + m.n_boundary, threads, m.grid.keys, m.grid.cell_start, m.grid.cell_end, m.b_grid.keys],
            [self._sweep_count, self._sweep_cell, self._sweep_color],
        )

    def _gauss_seidel_density_solve(self, st: FluidState) -> list[Stage | Loop]:
        """The density solve by Gauss-Seidel sweeps (``cosim.fluid.dfsph.gauss_seidel_density_sweep``): the warm
        start applied at once, then sweeps of one stage per cell colour, each sweep followed by the convergence
        test, until it passes."""
        m, prm = self.model, self.model.params
        pairs, b_pairs = self._solve_pairs()
        cells = [self._sweep_count, self._sweep_cell, self._sweep_color, m.grid.cell_start, m.grid.cell_end]
        colors = [
            self.lanes.launch(
                dfsph.gauss_seidel_density_sweep, self._sweep_threads(),
                [
                    prm, color, m.b_volume, *cells, m.b_grid.order, m.b_grid.cell_start, m.b_grid.cell_end, st.rho, self._alpha, self._dt, self._bv, *pairs,
                    self._b_rho, self._b_alpha, *b_pairs, st.mass,
                ],
                [self._v_star, st.kappa_density, self._b_kappa_density, self._lane_stats],
            )
            for color in range(dfsph.CELL_COLORS[self.config.dim])
        ]
        return [self._apply_stiffness(st, self._v_star, st.kappa_density), Loop(self._keep_going, (*colors, self._convergence_check(dfsph.SOLVE_DENSITY)))]

    def _capture(self) -> tuple | None:
        """Each lane's graphs of both parities' substeps (DFSPH's solve loops become conditional nodes on CUDA,
        while operations on the CPU; one lane on CUDA), or None, with the reason in :attr:`graph_capture_error`,
        where warp or the driver cannot capture them."""
        try:
            by_parity = [self.lanes.capture(program) for program in self._ops]
        except Exception as exc:  # warp raises RuntimeError and others (e.g. no conditional nodes before CUDA 12.4)
            self._capture_graphs = False
            self.graph_capture_error = f"{type(exc).__name__}: {exc}"
            return None
        return tuple(zip(*by_parity))

    def _run_substeps(self, count: int) -> None:
        """``count`` substeps: each lane replays its graphs (the lanes at once), or the operations run one by one
        (every lane's share in turn); the particle buffers swap after each substep."""
        if self.lanes.aborted:
            raise SimulationError("fluid: an earlier interval was interrupted inside its substeps; the liquid's state is undefined")
        if self._graphs is not None:
            parities = [(self._parity + k) % 2 for k in range(count)]
            self.lanes.replay([[graphs[p] for p in parities] for graphs in self._graphs])
        else:
            for k in range(count):
                run_serial(self._ops[(self._parity + k) % 2], self.operation_hook)
        if count % 2:
            self._parity ^= 1
            self.state, self._spare = self._spare, self.state

    def _check(self, first: int, t0: float, dt: float, rows_f: np.ndarray, rows_i: np.ndarray) -> None:
        cfg = self.config
        if not (
            rows_i[:, _CHECKED_COUNTS].any() or rows_f[:, 4].max() > cfg.max_density_error
            or self.energy_account.created > cfg.max_energy_creation
        ):  # the usual interval, found in one pass
            return
        checks = [
            (rows_i[:, 0] > 0, lambda s: f"{count_of(rows_i[s, 0], 'particle')} with a non-finite position, velocity or density"),
            (rows_i[:, 1] > 0, lambda s: f"{count_of(rows_i[s, 1], 'particle')} inside a vessel wall (deeper than {cfg.max_wall_penetration:g} dx)"),
            (rows_i[:, 6] > 0, lambda s: f"{count_of(rows_i[s, 6], 'particle')} with more neighbours than the pair list holds (over-compressed)"),
            (
                rows_f[:, 4] > cfg.max_density_error,
                lambda s: f"compression {rows_f[s, 4]:.3f} exceeds fluid.max_density_error = {cfg.max_density_error:g}",
            ),
        ]
        bad = [(int(np.argmax(mask)), describe) for mask, describe in checks if mask.any()]
        if bad:
            s, describe = min(bad, key=lambda b: b[0])
            raise FluidInstabilityError(first + s, t0 + (s + 1) * dt, describe(s))
        if self.energy_account.created > cfg.max_energy_creation:
            s = len(rows_f) - 1
            raise FluidInstabilityError(
                first + s, t0 + (s + 1) * dt,
                f"the numerics created {self.energy_account.created:.3g} M g L of energy beyond the walls' work "
                f"(fluid.max_energy_creation = {cfg.max_energy_creation:g}); a finer fluid.spacing, a larger "
                "fluid.sound_speed_factor or a gentler vessel motion",
            )

    # ---- readers (numpy, original particle order) ---------------------------------------------------------------
    def _in_id_order(self, arr: wp.array) -> np.ndarray:
        values = arr.numpy()
        out = np.empty_like(values)
        out[self.state.pid.numpy()] = values
        return out

    def positions(self) -> np.ndarray:
        """(N, 3) m, world frame (a deactivated particle keeps the position where it left)."""
        return self._in_id_order(self.state.x).astype(np.float64)

    def velocities(self) -> np.ndarray:
        """(N, 3) m/s."""
        return self._in_id_order(self.state.v).astype(np.float64)

    def densities(self) -> np.ndarray:
        """(N,) kg/m^3."""
        return self._in_id_order(self.state.rho).astype(np.float64)

    def pressures(self) -> np.ndarray:
        """(N,) Pa. WCSPH: from the equation of state after the last substep; DFSPH: rho kappa averaged over the
        last interval's substeps."""
        return self._in_id_order(self.state.p).astype(np.float64)

    def masses(self) -> np.ndarray:
        """(N,) SPH mass of each particle: kg (3-D), or kg per metre of depth (2-D), where a particle inside a vessel
        of depth d carries rho0 dx^2 ``depth_2d`` / d once it has entered it (``cosim.fluid.model``)."""
        return self._in_id_order(self.state.mass).astype(np.float64)

    def active_mask(self) -> np.ndarray:
        """(N,) bool: still simulated (False once spilled out of the domain)."""
        return self._in_id_order(self.state.active).astype(bool)

    def free_mask(self) -> np.ndarray:
        """(N,) bool: free liquid (outside every vessel, or back inside but not yet packed: summation density, no
        tension; ``FluidConfig.free_liquid``), under both solvers."""
        return self._in_id_order(self.state.free).astype(bool)

    def vessel_poses(self) -> list[Pose]:
        """Current world poses of the vessel frames (as simulated: projected onto the pour plane in 2-D)."""
        return [Pose(p.position, p.rotation) for p in self._poses]

    def wall_particles(self) -> np.ndarray:
        """(Nb, 3) m: world positions of the dummy wall particles at the current poses."""
        local = self.model.b_local.numpy().astype(np.float64)
        vessel = self.model.b_vessel.numpy()
        out = np.empty_like(local)
        for k, pose in enumerate(self._poses):
            out[vessel == k] = pose.transform(local[vessel == k])
        return out

    def vessel_wrenches(self) -> np.ndarray:
        """(V, 6): the liquid's force (N) and torque (N m) on each vessel about its centre of mass, world frame,
        averaged over the last interval's substeps (2-D: each particle's per-unit-depth force x its own depth,
        ``cosim.fluid.model``)."""
        return self._wrench.copy()

    @property
    def last_report(self) -> IntervalReport | None:
        return self._last_report

    def history(self) -> dict[str, np.ndarray]:
        """Every substep so far: 'dt' (s), 'time' (s, end of substep), 'max_speed', 'max_acceleration',
        'max_density_error', 'kinetic_energy', 'potential_energy' (J, -sum m g . x), 'nonfinite', 'wall_breaches', 'wall_corrections', 'active',
        'volume_in_vessel' (steps, V) m^3; DFSPH's 'divergence_iterations', 'density_iterations' and the errors
        its solves left, 'divergence_error', 'density_solve_error' (relative; zero under WCSPH)."""
        if not self._history:
            return {}
        dt = np.concatenate([h[0] for h in self._history])
        f = np.concatenate([h[1] for h in self._history])
        i = np.concatenate([h[2] for h in self._history])
        return {
            "dt": dt,
            "time": np.cumsum(dt),
            "max_speed": f[:, 0],
            "max_acceleration": f[:, 1],
            "max_density_error": f[:, 2],
            "max_compression": f[:, 4],
            "kinetic_energy": f[:, 3],
            "potential_energy": f[:, 7],
            "nonfinite": i[:, 0],
            "wall_breaches": i[:, 1],
            "wall_corrections": i[:, 2],
            "active": i[:, 3],
            "divergence_iterations": i[:, 4],
            "density_iterations": i[:, 5],
            "divergence_error": f[:, 5],
            "density_solve_error": f[:, 6],
            "volume_in_vessel": i[:, N_DIAG_INT_BASE:] * self.config.particle_volume,
        }
