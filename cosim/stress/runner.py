"""Run one stress configuration and measure it (no judgement here: :mod:`cosim.stress.classify` decides).

Energy account: the liquid's mechanical energy E = sum m (|v|^2 / 2 - g . x) (3-D equivalent masses; a particle
that left the domain keeps the energy it had at its last sample) is compared with the work W the moving walls did
on it, W = -sum over intervals of (F . v_com + tau . omega) dt, from the reaction wrench the solver reports on the
vessel (force F and torque tau about the vessel's centre of mass, averaged over the interval's substeps) and the
vessel's constant velocity within the interval. Viscosity, density diffusion and the wall guard only remove
energy, so E(t) - E(0) - W(t) > 0 is energy the numerics created. It is reported relative to M g L (liquid mass M,
vessel inner height L).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose, rotation_vector
from cosim.stress.matrix import DURATION, StressConfig
from cosim.validation.scripted import SAMPLE_INTERVAL, run_scripted


@dataclass(frozen=True)
class Measurement:
    """What one configuration did. Counts are particles; times s; energies relative to M g L.

    failure: the instability error's message ('' if the run finished). nonfinite: particles with a non-finite
    value (solver diagnostics plus the final state). leaked: particles ever inside a wall, through a wall, or (when
    the motion cannot spill) out of the vessel. max_density_error: max |rho - rho0| / rho0 over all substeps.
    energy_excess: max over samples of (E - E0 - W) / (M g L). energy_change, work_in: final E - E0 and W.
    dt_ratio_min: smallest substep / the step planned for the liquid at rest. speed_ratio: the largest particle
    speed / FluidConfig.max_expected_speed (c0 = sound_speed_factor x that speed assumes it stays <= 1).
    spilled_fraction: particles deactivated (left the domain) / all.
    """

    particles: int
    simulated_time: float
    steps: int
    failure: str
    nonfinite: int
    leaked: int
    worst_inside: int
    worst_through: int
    worst_escaped: int
    max_density_error: float
    energy_excess: float
    energy_change: float
    work_in: float
    dt_ratio_min: float
    speed_ratio: float
    guard_corrections: int
    spilled_fraction: float
    wall_time: float


class EnergyAccount:
    """E(t) - E(0) - W(t) of the liquid, sample by sample (see the module docstring); also the step the solver
    plans for the liquid at rest in a still vessel (s), the reference of the time-step reductions."""

    def __init__(self, com_local: np.ndarray, length: float):
        self.com_local = com_local
        self.length = length  # m, L of the energy scale M g L

    def start(self, solver: FluidSolver) -> None:
        cfg = solver.config
        self.mass = cfg.rest_density * cfg.particle_volume  # kg, 3-D equivalent per particle
        self.gravity = np.asarray(cfg.gravity, dtype=np.float64)
        self.scale = self.mass * solver.n_particles * cfg.gravity_magnitude * self.length  # J, M g L
        self.last = self._energies(solver.positions(), solver.velocities())
        self.e0 = float(self.last.sum())
        self.work = self.excess = self.change = 0.0
        self.nominal_dt = solver.plan_time_step(SAMPLE_INTERVAL, 0.0)[1]

    def _energies(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.mass * (0.5 * np.einsum("ij,ij->i", v, v) - x @ self.gravity)

    def sample(self, solver: FluidSolver, before: Pose, after: Pose, x: np.ndarray, active: np.ndarray) -> None:
        dt = SAMPLE_INTERVAL
        lin = (after.position - before.position) / dt
        omega = rotation_vector(after.rotation @ before.rotation.T) / dt
        com_offset = 0.5 * (before.rotation + after.rotation) @ self.com_local  # mid-interval, origin -> com
        v_com = lin + np.cross(omega, com_offset)
        wrench = solver.vessel_wrenches()[0]
        self.work -= float(wrench[:3] @ v_com + wrench[3:] @ omega) * dt
        e = self._energies(x, solver.velocities())
        self.last[active] = e[active]
        self.change = float(self.last.sum()) - self.e0
        self.excess = max(self.excess, self.change - self.work)


def _count_nonfinite(*arrays: np.ndarray) -> int:
    """Particles (rows) with any non-finite value, summed over the arrays."""
    return sum(int((~np.isfinite(a.reshape(len(a), -1))).any(axis=1).sum()) for a in arrays)


def measure(config: StressConfig, device: str = "cpu") -> Measurement:
    """Run ``config`` for :data:`DURATION` and measure it; an instability ends the run early (``failure``)."""
    spec = config.spec()
    start = time.perf_counter()
    energy = EnergyAccount(spec.com_local, spec.inner_height)
    run = run_scripted(spec, config.fill_depth, config.fluid_config(), config.pose_script(), DURATION, device=device,
                       can_spill=config.can_spill, observer=energy)
    solver, leaks = run.solver, run.leaks
    hist = solver.history()
    nonfinite = (int(hist["nonfinite"].sum()) if hist else 0) + _count_nonfinite(
        solver.positions(), solver.velocities(), solver.densities())
    return Measurement(
        particles=solver.n_particles,
        simulated_time=solver.time,
        steps=solver.step_count,
        failure=run.failure,
        nonfinite=nonfinite,
        leaked=leaks.leaked_count,
        worst_inside=leaks.worst_inside,
        worst_through=leaks.worst_through,
        worst_escaped=leaks.worst_escaped,
        max_density_error=float(hist["max_density_error"].max()) if hist else 0.0,
        energy_excess=energy.excess / energy.scale,
        energy_change=energy.change / energy.scale,
        work_in=energy.work / energy.scale,
        dt_ratio_min=float(hist["dt"].min()) / energy.nominal_dt if hist else 1.0,
        speed_ratio=float(hist["max_speed"].max()) / solver.config.max_expected_speed if hist else 0.0,
        guard_corrections=int(hist["wall_corrections"].sum()) if hist else 0,
        spilled_fraction=1.0 - float(solver.active_mask().mean()),
        wall_time=time.perf_counter() - start,
    )
