"""A small 2-D tank of liquid, tilted and slid over a few intervals: the run the solver's execution variants (graph
replay, CPU lanes) are compared on, to the bit."""

from __future__ import annotations

import math

import pytest

from cosim.fluid.config import GRAVITY, DensityIteration, FluidConfig, PressureSolver
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose, rotation_y
from cosim.vessel import VesselSpec

B = 0.191  # m, the width of the pouring vessel of Camporredondo et al. (2019)
FILL = 0.1  # m
# The solver variants the execution variants are compared under: (pressure solver, DFSPH's density iteration)
SOLVER_VARIANTS = [
    pytest.param(PressureSolver.WCSPH, DensityIteration.GAUSS_SEIDEL, id="wcsph"),
    pytest.param(PressureSolver.DFSPH, DensityIteration.GAUSS_SEIDEL, id="dfsph-gauss_seidel"),
    pytest.param(PressureSolver.DFSPH, DensityIteration.JACOBI, id="dfsph-jacobi"),
]


def tank(
    solver: PressureSolver, across: int, graphs: bool = True, threads: int = 0, iteration: DensityIteration = DensityIteration.GAUSS_SEIDEL,
) -> FluidSolver:
    """The tank (B wide, filled FILL deep, ``across`` particles across) on the CPU."""
    vessel = VesselSpec(name="tank", inner_width=B, inner_depth=0.1, inner_height=0.2)
    cfg = FluidConfig(
        dim=2, spacing=B / across, pressure_solver=solver, max_expected_speed=2 * math.sqrt(GRAVITY * FILL),
        domain_min=(-0.3, -0.15, -0.1), domain_max=(0.3, 0.15, 0.4), cpu_threads=threads, density_iteration=iteration,
    )
    return FluidSolver(cfg, [vessel], [Pose()], fill_vessel(vessel, FILL, cfg), graphs=graphs)


def shake(fluid: FluidSolver, intervals: int, tilt: float) -> None:
    """Tilt (up to ``tilt`` rad) and slide the tank over ``intervals`` intervals of 10 ms, then one of 40 ms (more
    substeps than any before: the diagnostics rows grow and the substep is captured again)."""
    for k in range(1, intervals + 1):
        t = 0.01 * k
        fluid.set_vessel_poses([Pose((0.02 * math.sin(8 * t), 0.0, 0.0), rotation_y(tilt * math.sin(6 * t)))])
        fluid.advance(0.01)
    fluid.set_vessel_poses([Pose((0.0, 0.0, 0.0), rotation_y(0.1))])
    fluid.advance(0.04)
