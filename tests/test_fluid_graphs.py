"""Captured substeps (``FluidSolver(graphs=True)``, the default): on the CPU warp replays them from its operation
stream; the liquid must evolve exactly as with the launches run one by one, through vessel motion, DFSPH's solve
loops and a re-capture when an interval needs more substeps than any before."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.fluid.config import GRAVITY, FluidConfig, PressureSolver
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose, rotation_y
from cosim.vessel import VesselSpec

B = 0.191  # m, the seed's vessel width
FILL = 0.1  # m


def _tank(solver: PressureSolver, graphs: bool) -> FluidSolver:
    tank = VesselSpec(name="tank", inner_width=B, inner_depth=0.1, inner_height=0.2)
    cfg = FluidConfig(
        dim=2, spacing=B / 12, pressure_solver=solver, max_expected_speed=2 * math.sqrt(GRAVITY * FILL),
        domain_min=(-0.3, -0.15, -0.1), domain_max=(0.3, 0.15, 0.4),
    )
    return FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, FILL, cfg), graphs=graphs)


def _shake(fluid: FluidSolver) -> None:
    """Tilt and slide the tank over 20 intervals of 10 ms, then one of 40 ms (more substeps than any before: the
    diagnostics rows grow and the substep is captured again)."""
    for k in range(1, 21):
        t = 0.01 * k
        fluid.set_vessel_poses([Pose((0.02 * math.sin(8 * t), 0.0, 0.0), rotation_y(0.15 * math.sin(6 * t)))])
        fluid.advance(0.01)
    fluid.set_vessel_poses([Pose((0.0, 0.0, 0.0), rotation_y(0.1))])
    fluid.advance(0.04)


@pytest.mark.parametrize("solver", [PressureSolver.WCSPH, PressureSolver.DFSPH])
def test_replayed_substeps_match_the_launches_one_by_one(solver):
    replayed, launched = _tank(solver, True), _tank(solver, False)
    for fluid in (replayed, launched):
        _shake(fluid)
    assert replayed.graph_capture_error is None and replayed._graphs is not None  # it did replay
    assert launched._graphs is None
    assert replayed.step_count == launched.step_count
    for read in (FluidSolver.positions, FluidSolver.velocities, FluidSolver.densities, FluidSolver.pressures, FluidSolver.vessel_wrenches):
        np.testing.assert_array_equal(read(replayed), read(launched))
    for key, values in launched.history().items():
        np.testing.assert_array_equal(replayed.history()[key], values, err_msg=key)
