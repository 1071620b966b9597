"""The fluid's work-skipping options: the neighbour grid reset restricted to occupied cells gives the very same
liquid as resetting the whole domain; the fixed time step is the expected-speed step, the adaptive one follows
the flow."""

import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, GridReset
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.validation.scripted import SAMPLE_INTERVAL, domain_around, shake_sideways
from cosim.vessel import seed_pouring_vessel


def _shaken(duration: float = 0.1, **overrides) -> FluidSolver:
    spec = seed_pouring_vessel()
    lo, hi = domain_around(spec, 0.02)
    settings = dict(dim=2, spacing=spec.inner_width / 16, pressure_solver="wcsph", max_expected_speed=1.4, domain_min=lo, domain_max=hi)
    cfg = FluidConfig(**(settings | overrides))
    pose_at = shake_sideways(0.02, 12.0)
    solver = FluidSolver(cfg, [spec], [pose_at(0.0)], fill_vessel(spec, 0.1, cfg), device="cpu")
    while solver.time < duration - 1e-9:
        solver.set_vessel_poses([pose_at(solver.time + SAMPLE_INTERVAL)])
        solver.advance(SAMPLE_INTERVAL)
    return solver


def test_occupied_cell_reset_gives_the_same_liquid_as_resetting_the_whole_grid():
    occupied = _shaken(grid_reset=GridReset.OCCUPIED)
    whole = _shaken(grid_reset=GridReset.WHOLE)
    assert occupied.step_count == whole.step_count
    np.testing.assert_array_equal(occupied.positions(), whole.positions())
    np.testing.assert_array_equal(occupied.velocities(), whole.velocities())
    np.testing.assert_array_equal(occupied.vessel_wrenches(), whole.vessel_wrenches())


@pytest.mark.parametrize("solver_name", ["wcsph", "dfsph"])
def test_fixed_time_step_is_the_expected_speed_step(solver_name):
    fixed = _shaken(adaptive_time_step=False, pressure_solver=solver_name)
    cfg = fixed.config
    sound = cfg.sound_speed if solver_name == "wcsph" else 0.0
    planned = cfg.cfl * cfg.smoothing_length / (sound + cfg.max_expected_speed)
    # whole substeps per 2 ms interval: the step is the interval over ceil(interval / planned)
    np.testing.assert_allclose(fixed.history()["dt"], SAMPLE_INTERVAL / math.ceil(SAMPLE_INTERVAL / planned - 1e-9), rtol=1e-12)


def test_adaptive_time_step_shortens_when_the_flow_outruns_the_expected_speed():
    # the 2 cm shake at 12 rad/s moves the walls at up to 0.24 m/s, past the 0.2 m/s this liquid was told to expect
    fixed = _shaken(adaptive_time_step=False, max_expected_speed=0.2)
    adaptive = _shaken(max_expected_speed=0.2)
    assert adaptive.history()["dt"].min() < fixed.history()["dt"].min()


def test_option_values_are_checked():
    with pytest.raises(InputError, match="fluid.adaptive_time_step"):
        FluidConfig(adaptive_time_step="yes")
    with pytest.raises(InputError, match="fluid.grid_reset"):
        FluidConfig(grid_reset="sparse")
