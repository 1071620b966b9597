"""Captured substeps (``FluidSolver(graphs=True)``, the default): on the CPU warp replays them from its operation
stream; the liquid must evolve exactly as with the launches run one by one, through vessel motion, DFSPH's solve
loops and a re-capture when an interval needs more substeps than any before."""

from __future__ import annotations

import numpy as np
import pytest

from cosim.fluid.solver import FluidSolver
from tests.support.shaken_tank import SOLVER_VARIANTS, shake, tank


@pytest.mark.parametrize(("solver", "iteration"), SOLVER_VARIANTS)
def test_replayed_substeps_match_the_launches_one_by_one(solver, iteration):
    replayed, launched = tank(solver, 12, graphs=True, iteration=iteration), tank(solver, 12, graphs=False, iteration=iteration)
    for fluid in (replayed, launched):
        shake(fluid, intervals=20, tilt=0.15)
    assert replayed.graph_capture_error is None and replayed.runner.replays_graphs  # it did replay
    assert not launched.runner.replays_graphs
    assert replayed.step_count == launched.step_count
    for read in (FluidSolver.positions, FluidSolver.velocities, FluidSolver.densities, FluidSolver.pressures, FluidSolver.vessel_wrenches):
        np.testing.assert_array_equal(read(replayed), read(launched))
    for key, values in launched.history().items():
        np.testing.assert_array_equal(replayed.history()[key], values, err_msg=key)
