"""The substeps of an interval: the time step from the CFL, force and viscous criteria."""

from __future__ import annotations

import math

from cosim.fluid.config import FluidConfig, PressureSolver

FORCE_CFL = 0.25  # Monaghan's force criterion dt <= 0.25 sqrt(h / a_max)
VISCOUS_CFL = 0.125  # viscous criterion dt <= 0.125 h^2 / nu


def stable_time_step(cfg: FluidConfig, wall_speed: float, max_speed: float, max_accel: float) -> float:
    """The largest stable dt (s) for the liquid whose last interval reached ``max_speed`` (m/s) and ``max_accel``
    (m/s^2) in vessels whose walls move at up to ``wall_speed`` (m/s): the CFL condition dt <= cfl h / signal,
    with the signal speed acoustic for WCSPH (c0 + the flow's and the wall's speed) and the flow's alone for DFSPH
    (at least ``max_expected_speed``: a jet forms within an interval), and the force criterion; with
    ``adaptive_time_step`` off, the fixed step; both bounded by the viscous criterion."""
    h = cfg.smoothing_length
    if not cfg.adaptive_time_step:
        dt = cfg.fixed_time_step
    else:
        if cfg.pressure_solver is PressureSolver.WCSPH:
            signal = cfg.sound_speed + max_speed + wall_speed
        else:
            signal = max(cfg.max_expected_speed, max_speed) + wall_speed
        dt = cfg.cfl * h / max(signal, 1e-9)
        dt = min(dt, FORCE_CFL * math.sqrt(h / max(max_accel, 1e-9)))
    if cfg.kinematic_viscosity > 0.0:
        dt = min(dt, VISCOUS_CFL * h * h / cfg.kinematic_viscosity)
    return dt


def split_interval(duration: float, dt: float) -> tuple[int, float]:
    """(substeps, their dt): the fewest equal substeps of ``duration`` (s) no longer than ``dt``."""
    n = max(1, math.ceil(duration / dt - 1e-9))
    return n, duration / n
