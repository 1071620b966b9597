"""The substeps of an interval: the time step from the CFL, force and viscous criteria."""

from __future__ import annotations

import math
from typing import NamedTuple

from cosim.fluid.config import FluidConfig, PressureSolver, ViscousTimeStep

FORCE_CFL = 0.25  # Monaghan's force criterion dt <= 0.25 sqrt(h / a_max)
VISCOUS_CFL = 0.125  # viscous criterion dt <= 0.125 h^2 / (nu + nu_art)


def artificial_kinematic_viscosity(cfg: FluidConfig, flow_speed: float, wall_speed: float) -> float:
    """m^2/s, the largest kinematic viscosity the artificial viscosity stands for, nu_art = alpha h v_sig / (2 (dim + 2))
    (Monaghan 2005, "Smoothed particle hydrodynamics", Rep. Prog. Phys. 68: alpha h c / 8 in 2-D, / 10 in 3-D), with
    the largest alpha any pair uses and the largest velocity scale v_sig = c + beta w (``FluidConfig.viscosity_speed``):
    c0, or with the signal velocity the fastest approach w the planned flow allows, two particles head on at
    ``flow_speed`` (m/s) or one at ``flow_speed`` against a wall moving at ``wall_speed`` (m/s)."""
    return TimeStepPlanner(cfg).artificial_kinematic_viscosity(flow_speed, wall_speed)


def stable_time_step(cfg: FluidConfig, wall_speed: float, max_speed: float, max_accel: float) -> float:
    """The largest stable dt (s) for the liquid whose last interval reached ``max_speed`` (m/s) and ``max_accel``
    (m/s^2) in vessels whose walls move at up to ``wall_speed`` (m/s) (:meth:`TimeStepPlanner.stable_time_step`)."""
    return TimeStepPlanner(cfg).stable_time_step(wall_speed, max_speed, max_accel)


class TimeStepLimits(NamedTuple):
    """Each criterion's largest stable dt (s) for one interval; inf where a criterion does not apply. ``advection``:
    the CFL condition (with ``adaptive_time_step`` off, the fixed step); ``force``: Monaghan's force criterion (inf
    with the fixed step); ``viscous``: the viscous diffusion criterion (inf without viscosity)."""

    advection: float
    force: float
    viscous: float

    @property
    def step(self) -> float:
        """s, the step: the shortest of the three."""
        return min(self.advection, self.force, self.viscous)

    @property
    def binding(self) -> str:
        """The name of the criterion that sets the step (the first of the shortest)."""
        return self._fields[self.index(self.step)]


class TimeStepPlanner:
    """The time-step criteria of one configuration, its constants read once (the solver plans every interval, and
    each of the configuration's derived quantities is a property computed on every read): the same operations in
    the same order as on the configuration itself, so the same bits."""

    def __init__(self, cfg: FluidConfig):
        self.h = cfg.smoothing_length
        self.adaptive = cfg.adaptive_time_step
        self.max_expected_speed = cfg.max_expected_speed
        self.fixed_time_step = cfg.fixed_time_step
        self.acoustic = cfg.pressure_solver is PressureSolver.WCSPH
        self.sound_speed = cfg.sound_speed
        self.cfl = cfg.cfl
        self.kinematic_viscosity = cfg.kinematic_viscosity
        self.alpha = max(cfg.alpha, cfg.free_liquid_alpha) if cfg.free_liquid else cfg.alpha
        self.viscosity_speed = cfg.viscosity_speed
        self.approach_weight = cfg.viscosity_approach_weight
        self.measured_approach = cfg.viscous_time_step is ViscousTimeStep.MEASURED_APPROACH
        self.dim = cfg.dim

    def artificial_kinematic_viscosity(self, flow_speed: float, wall_speed: float) -> float:
        """m^2/s, nu_art = alpha h v_sig / (2 (dim + 2)) (:func:`artificial_kinematic_viscosity`)."""
        speed = self.viscosity_speed + self.approach_weight * max(2.0 * flow_speed, flow_speed + wall_speed)
        return self.alpha * self.h * speed / (2.0 * (self.dim + 2))

    def stable_time_step(self, wall_speed: float, max_speed: float, max_accel: float) -> float:
        """The largest stable dt (s) for the liquid whose last interval reached ``max_speed`` (m/s) and ``max_accel``
        (m/s^2) in vessels whose walls move at up to ``wall_speed`` (m/s): the shortest of :meth:`limits`."""
        return self.limits(wall_speed, max_speed, max_accel).step

    def limits(self, wall_speed: float, max_speed: float, max_accel: float) -> TimeStepLimits:
        """Each criterion's dt (s) for the liquid whose last interval reached ``max_speed`` (m/s) and ``max_accel``
        (m/s^2) in vessels whose walls move at up to ``wall_speed`` (m/s): the CFL condition dt <= cfl h / signal,
        with the signal speed acoustic for WCSPH (c0 + the flow's and the wall's speed) and for DFSPH the fastest
        approach the last interval allows, a particle at ``max_speed`` against a wall at ``wall_speed``, but at least
        ``max_expected_speed`` (a jet forms within an interval; the floor is the jet's own speed relative to the
        vessel it lands in, not a speed to add the walls' to), and the force criterion; with
        ``adaptive_time_step`` off, the fixed step alone. Either way the viscous diffusion criterion
        dt <= 0.125 h^2 / (nu + nu_art) (Morris, Fox and Zhu 1997, "Modeling low Reynolds number incompressible flows
        using SPH", J. Comput. Phys. 136), nu_art (:meth:`artificial_kinematic_viscosity`) at the approach speed
        ``viscous_time_step`` takes: 'planned_approach', the flow speed DFSPH's CFL condition plans with;
        'measured_approach', ``max_speed`` itself (the fixed step, which measures nothing, takes
        ``max_expected_speed`` and still walls either way). nu_art being alpha h v_sig / (2 (dim + 2)), the criterion
        is Monaghan's dt <= C h / max v_sig,ij (1997, "SPH and Riemann solvers", J. Comput. Phys. 136) with
        C = 0.125 x 2 (dim + 2) / alpha, at the planned or at the measured approach."""
        h = self.h
        force = math.inf
        if not self.adaptive:
            flow_speed, wall_speed = self.max_expected_speed, 0.0  # the fixed step measures nothing
            advection = self.fixed_time_step
            approach_speed = flow_speed
        else:
            flow_speed = max(self.max_expected_speed, max_speed)
            if self.acoustic:
                signal = self.sound_speed + max_speed + wall_speed
            else:
                signal = max(self.max_expected_speed, max_speed + wall_speed)
            advection = self.cfl * h / max(signal, 1e-9)
            force = FORCE_CFL * math.sqrt(h / max(max_accel, 1e-9))
            approach_speed = max_speed if self.measured_approach else flow_speed
        diffusivity = self.kinematic_viscosity + self.artificial_kinematic_viscosity(approach_speed, wall_speed)
        viscous = VISCOUS_CFL * h * h / diffusivity if diffusivity > 0.0 else math.inf
        return TimeStepLimits(advection, force, viscous)


def split_interval(duration: float, dt: float) -> tuple[int, float]:
    """(substeps, their dt): the fewest equal substeps of ``duration`` (s) no longer than ``dt``."""
    n = max(1, math.ceil(duration / dt - 1e-9))
    return n, duration / n
