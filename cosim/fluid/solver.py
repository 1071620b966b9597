"""The SPH liquid solver: the public object of ``cosim.fluid``.

Time is advanced in intervals (the coupling's MuJoCo step, or any duration): before an interval the caller gives
each vessel's pose at the END of the interval (:meth:`FluidSolver.set_vessel_poses`); the vessel then moves from
its current pose to that one at constant linear and angular velocity while the liquid takes as many equal
substeps as the CFL, force and viscous criteria need (``cosim.fluid.time_step``, from the previous interval's
maxima and the wall speed). Each substep is the configured pressure solver's step, a sequence of named stages
(``cosim.fluid.wcsph_step.WCSPHStep``, ``cosim.fluid.dfsph_step.DFSPHStep``), run entirely on the device: only the
interval's plan and its diagnostics cross. ``cosim.fluid.runner`` records the substeps and replays them as captured
graphs, split over CPU threads on the CPU. After the interval the per-substep diagnostics are checked and an
instability raises :class:`FluidInstabilityError` naming the step and what broke (``cosim.fluid.instability``).
Results come back as numpy arrays in the particles' original order.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Sequence

import numpy as np
import warp as wp

from cosim.errors import InputError
from cosim.fluid.config import DensityIteration, FluidConfig, InitialState, PressureSolver
from cosim.fluid.device_layout import DeviceLayout, layout_for
from cosim.fluid.dfsph_step import DFSPHStep
from cosim.fluid.diagnostics import StepDiagnostics, SubstepRows
from cosim.fluid.energy import EnergyAccount
from cosim.fluid.instability import FluidInstabilityError, check_interval
from cosim.fluid.lanes import Lanes, lane_count
from cosim.fluid.memory import allocation_failure_refused
from cosim.fluid.model import FluidModel, FluidState, build_model
from cosim.fluid.relaxation import RELAX_INTERVAL, RELAX_TIME_CAP, STALL_TIME, RelaxationReport, relax_liquid, stop_speed
from cosim.fluid.runner import SubstepRunner
from cosim.fluid.runtime import resolve_device
from cosim.fluid.seeding import ParticleSet
from cosim.fluid.substep import SubstepScratch
from cosim.fluid.time_step import TimeStepPlanner, split_interval
from cosim.fluid.wcsph_step import WCSPHStep
from cosim.frames import Pose, rotation_vector, rotation_y, tilt_about_y
from cosim.vessel import VesselSpec

__all__ = ["FluidInstabilityError", "FluidSolver", "IntervalReport"]


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
      graphs: replay each substep as one captured graph after the first interval (``cosim.fluid.runner``); the
        operations one by one where capture fails (:attr:`graph_capture_error` says why) or when False.
      layout: how the pair tables, the wrench reduction and the atomic accumulators are laid out
        (:mod:`cosim.fluid.device_layout`); None: the device kind's own. The particles are the same under any.
      relax_start: with ``config.initial_state`` 'relaxed', settle the liquid before t = 0 (``cosim.fluid.relaxation``;
        :attr:`relaxation` reports it); False for a liquid that starts moving or that its vessels do not hold at
        rest (a released column), which starts as given, with no offsets.
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
        relax_start: bool = True,
    ):
        if len(vessels) != len(poses):
            raise InputError(f"fluid: {len(vessels)} vessels but {len(poses)} poses")
        if len(particles) == 0:
            raise InputError("fluid: the initial liquid holds no particle")
        if config.dim == 2 and not (config.domain_min[1] < 0.0 < config.domain_max[1]):
            raise InputError("fluid.domain_min[1]..domain_max[1]: must contain y = 0 (the pour plane) in 2-D")
        self.config = config
        self.device = resolve_device(device)
        self._synchronize = self.device.is_cuda  # after the substeps, for their wall time
        dfsph = config.pressure_solver is PressureSolver.DFSPH
        self.layout = layout or layout_for(self.device, dfsph and config.density_iteration is DensityIteration.GAUSS_SEIDEL)
        self.n_particles = len(particles)
        self.lanes = Lanes(lane_count(config.cpu_threads, self.n_particles, self.device), self.device)
        self.time = 0.0
        self.step_count = 0
        self.substep_wall_time = 0.0  # s of wall clock spent in the substeps (device work included), for benchmarks
        self._poses = [self._planar(p) for p in poses]
        self._targets = list(self._poses)
        self._lin_vel = self._ang_vel = np.zeros((len(vessels), 3))
        self._last_max_speed = 0.0
        self._last_max_accel = config.gravity_magnitude
        self._time_steps = TimeStepPlanner(config)
        self._history: list[tuple[int, float, SubstepRows]] = []  # each interval's substeps, their dt (s), their rows
        self._last_report: IntervalReport | None = None
        self._wrench = np.zeros((len(vessels), 6))
        with allocation_failure_refused(self.device):
            self.model: FluidModel = build_model(config, tuple(vessels), self.n_particles, self.device, self.layout.atomic_replicas)
            state = self._seeded_state(particles)
            self.scratch = SubstepScratch(self.model, self.lanes, self.layout)
            self.step: WCSPHStep | DFSPHStep = DFSPHStep(self.model, self.scratch, self.lanes) if dfsph else WCSPHStep(self.model, self.scratch)
            self.step.initialise(state)
            self.runner = SubstepRunner(self.lanes, self.step.substep, state, FluidState.allocate(self.n_particles, self.device), graphs)
        self.scratch.set_motions(self._poses, self._lin_vel, self._ang_vel, self._lin_vel, self._ang_vel)
        self.energy_account = EnergyAccount(config, vessels, particles.positions, particles.velocities, self.step.internal_energy(state))
        self.relaxation: RelaxationReport | None = None
        if relax_start and config.initial_state is InitialState.RELAXED:
            self.relaxation = self.relax(RELAX_TIME_CAP, RELAX_INTERVAL, stop_speed(config.gravity_magnitude), STALL_TIME)

    # ---- set-up ----------------------------------------------------------------------------------------------
    def _planar(self, pose: Pose) -> Pose:
        """``pose`` as the solver keeps it: its own copy, projected onto the pour plane in 2-D."""
        if self.config.dim == 3:
            return Pose(pose.position, pose.rotation)
        planar = Pose(pose.position, rotation_y(tilt_about_y(pose.rotation)))  # Pose copies the position
        planar.position[1] = 0.0
        return planar

    def _seeded_state(self, particles: ParticleSet) -> FluidState:
        state = FluidState.allocate(self.n_particles, self.device)
        state.x.assign(particles.positions.astype(np.float32))
        state.v.assign(particles.velocities.astype(np.float32))
        state.rho.assign(particles.densities.astype(np.float32))
        state.active.fill_(1)
        state.mass.fill_(self.config.particle_mass)
        state.pid.assign(np.arange(self.n_particles, dtype=np.int32))
        return state

    @property
    def state(self) -> FluidState:
        """The liquid's current particle arrays (device, cell order)."""
        return self.runner.state

    @property
    def graph_capture_error(self) -> str | None:
        """Why the substeps could not be captured as graphs (None: captured, or not asked for)."""
        return self.runner.capture_error

    @property
    def operation_hook(self) -> Callable[[Callable[[], None]], None] | None:
        """A profiler's hook, run for each operation of substeps launched one by one (``cosim.fluid.runner``)."""
        return self.runner.operation_hook

    @operation_hook.setter
    def operation_hook(self, hook: Callable[[Callable[[], None]], None] | None) -> None:
        self.runner.operation_hook = hook

    # ---- driving ---------------------------------------------------------------------------------------------
    def set_vessel_poses(self, poses: Sequence[Pose]) -> None:
        """World poses of the vessel frames at the end of the next :meth:`advance` interval."""
        if len(poses) != self.model.n_vessels:
            raise InputError(f"fluid: {self.model.n_vessels} vessels but {len(poses)} poses given")
        for k, pose in enumerate(poses):
            if not (math.isfinite(np.add.reduce(pose.position)) and math.isfinite(np.add.reduce(pose.rotation, axis=None))) and not (
                np.all(np.isfinite(pose.position)) and np.all(np.isfinite(pose.rotation))
            ):  # a finite sum (the ufunc's own, without ndarray.sum's wrappers) is the cheap proof (a NaN or inf
                # propagates); an overflowing one is looked at closely
                raise InputError(f"fluid: vessel {self.model.vessel_specs[k].name} pose is not finite")
        self._targets = [self._planar(p) for p in poses]

    def hold_vessels(self) -> None:
        """The vessels stay at their current poses through the next :meth:`advance` interval."""
        self._targets = list(self._poses)

    def plan_time_step(self, duration: float, wall_speed: float) -> tuple[int, float]:
        """(substeps, dt) for an interval of ``duration`` s with walls moving at up to ``wall_speed`` m/s
        (``cosim.fluid.time_step``); raises :class:`FluidInstabilityError` below ``min_time_step``."""
        dt = self._time_steps.stable_time_step(wall_speed, self._last_max_speed, self._last_max_accel)
        if dt < self.config.min_time_step:
            raise FluidInstabilityError(self.step_count, self.time, f"time step collapsed to {dt:.3g} s (< fluid.min_time_step)")
        return split_interval(duration, dt)

    def advance(self, duration: float) -> IntervalReport:
        """Advance the liquid by ``duration`` (s), moving each vessel to its target pose meanwhile."""
        if not (duration > 0.0 and math.isfinite(duration)):
            raise InputError(f"fluid.advance: duration must be > 0 s, got {duration}")
        m = self.model
        # (V, 3) velocities, divided once for all vessels; each norm sqrt(v . v) on the row itself (the bits of
        # ``vector_norm``, whose dispatch would cost more than the arithmetic)
        lin = np.array([t.position - p.position for p, t in zip(self._poses, self._targets)]).reshape(-1, 3) / duration
        ang = np.array([rotation_vector(t.rotation @ p.rotation.T) for p, t in zip(self._poses, self._targets)]).reshape(-1, 3) / duration
        wall_speed = max((math.sqrt(v.dot(v)) + math.sqrt(w.dot(w)) * reach for v, w, reach in zip(lin, ang, m.b_reach)), default=0.0)
        n_sub, dt = self.plan_time_step(duration, wall_speed)
        self.scratch.set_motions(self._poses, lin, ang, (lin - self._lin_vel) / duration, (ang - self._ang_vel) / duration)
        self._lin_vel, self._ang_vel = lin, ang
        if self.scratch.diagnostics.ensure(n_sub):
            self.runner.invalidate()
        self.step.begin_interval(self.state, n_sub)
        self.scratch.begin_interval(dt)
        start = time.perf_counter()
        self.runner.run(n_sub)
        if self._synchronize:
            wp.synchronize_device(self.device)  # the diagnostics copy below waits for the device anyway
        self.substep_wall_time += time.perf_counter() - start
        self.runner.capture_if_due()
        rows = self.scratch.diagnostics.read(n_sub)
        first, t0 = self.step_count, self.time
        self.step_count += n_sub
        self.time += duration
        self._history.append((n_sub, dt, rows))
        self._wrench = self.scratch.mean_wrench(m.n_vessels, n_sub)
        self.energy_account.update(
            float(rows.kinetic_energy[-1] + rows.internal_energy[-1]), float(rows.potential_energy[-1]), float(rows.removed_energy.sum()),
            self._wrench, self._poses, lin, ang, duration,
        )
        self._poses = list(self._targets)
        check_interval(self.config, rows, first, t0, dt, self.energy_account.created)
        self._last_max_speed = float(np.maximum.reduce(rows.max_speed))  # ndarray.max's own reduction, unwrapped
        self._last_max_accel = float(np.maximum.reduce(rows.max_acceleration))
        n, volume = self.n_particles, self.config.particle_volume
        self._last_report = IntervalReport(n_sub, dt, lambda: rows.record(n_sub - 1, first + n_sub - 1, t0 + (n_sub - 1) * dt + dt, dt, n, volume))
        return self._last_report

    def relax(self, duration: float, interval: float, stop: float = 0.0, stall: float = math.inf) -> RelaxationReport:
        """Let the seeded liquid settle into the solver's own rest state, then start the run from it at t = 0
        (:func:`cosim.fluid.relaxation.relax_liquid`): the vessels held at their poses, intervals of ``interval``
        s, every particle's velocity set to zero after each, for ``duration`` s, or until no particle regained more
        than ``stop`` m/s within an interval (0: never), or until that largest speed has set no new low for
        ``stall`` s (inf: never). A seeding that is not the lattice the rest density is normalised on (rings in a
        cylinder) starts with local density errors of a few per cent; DFSPH corrects a density error within one
        substep by a velocity of error times spacing over dt, so released at once the liquid would carry that
        velocity on (hundreds of mm/s, which the liquid's small viscosity does not remove). Here the pressure
        solve's position corrections are kept and the velocity that made them is dropped."""
        return relax_liquid(self, duration, interval, stop, stall)

    def restart_at_rest(self) -> None:
        """The clock, the step count, the history and the energy account restart from the liquid as it is, at rest
        (its velocities already zero): the end of a relaxation."""
        self.time = 0.0
        self.step_count = 0
        self._history = []
        self._last_max_speed = 0.0
        self.energy_account = EnergyAccount(self.config, self.model.vessel_specs, self.positions(), self.velocities(),
                                            self.step.internal_energy(self.state))

    @property
    def last_max_speed(self) -> float:
        """m/s: the largest particle speed of the last interval's substeps."""
        return self._last_max_speed

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
        """(N,) bool: free liquid (outside every vessel or at the free surface, by ``FluidConfig.free_liquid_rule``, or
        not yet packed again: summation density, no tension; ``FluidConfig.free_liquid``), under both solvers."""
        return self._in_id_order(self.state.free).astype(bool)

    def free_surface_indicator(self) -> np.ndarray:
        """(N,) Marrone et al. (2010)'s free-surface indicator of each particle at the last substep's start (about 1
        inside the liquid, 0.5 at a flat surface, 0 alone; ``cosim.fluid.free_surface``). Measured only under
        ``FluidConfig.free_liquid_rule`` 'free_surface' (with ``free_liquid``) or WCSPH's ``tension_treatment``
        'tic'; otherwise zeros."""
        return self._in_id_order(self.scratch.free_surface).astype(np.float64)

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
        dt = np.concatenate([np.full(n_sub, step) for n_sub, step, _ in self._history])
        rows = SubstepRows.concatenate([h[2] for h in self._history])
        return {
            "dt": dt,
            "time": np.cumsum(dt),
            "max_speed": rows.max_speed,
            "max_acceleration": rows.max_acceleration,
            "max_density_error": rows.max_density_error,
            "max_compression": rows.max_compression,
            "kinetic_energy": rows.kinetic_energy,
            "potential_energy": rows.potential_energy,
            "nonfinite": rows.nonfinite,
            "wall_breaches": rows.wall_breaches,
            "wall_corrections": rows.wall_corrections,
            "active": rows.active,
            "divergence_iterations": rows.divergence_iterations,
            "density_iterations": rows.density_iterations,
            "divergence_error": rows.divergence_error,
            "density_solve_error": rows.density_solve_error,
            "volume_in_vessel": rows.inside * self.config.particle_volume,
        }
