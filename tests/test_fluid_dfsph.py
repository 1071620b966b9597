"""DFSPH (divergence-free SPH): a resting column stays at rest and weighs what it should, moving vessels do not
leak, runs are deterministic, and the time step follows the flow instead of the artificial sound speed."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.fluid.config import GRAVITY, FluidConfig, PressureSolver
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose, rotation_y
from cosim.pour_scene import FluidSettings
from cosim.validation import hydrostatic
from cosim.vessel import VesselSpec

B = 0.191  # m, the seed's vessel width
FILL = 0.1  # m
# A resting column must stay at rest: after REST_SETTLE of simulated time its fastest particle moves slower than this
# fraction of the shallow-water wave speed sqrt(g H) (the scale of any sloshing the start-up could excite). DFSPH
# measured 7.0 % at 12 particles across after 1 s: residual motion of its iterative pressure (the solves stop at a
# tolerance and only correct compression; see the warm starts in cosim.fluid.dfsph); WCSPH 0.45 %. The bound is
# what DFSPH is held to (a standing residual slosh of a few mm), not WCSPH's level.
REST_SPEED_FRACTION = 0.1
REST_SETTLE = 1.0  # s


def _tank(solver=PressureSolver.DFSPH, across=12, dim=2, smoothing_ratio=1.5):
    tank = VesselSpec(name="tank", inner_width=B, inner_depth=B if dim == 3 else 0.1, inner_height=0.2)
    cfg = FluidConfig(
        dim=dim, spacing=B / across, smoothing_ratio=smoothing_ratio, pressure_solver=solver,
        max_expected_speed=2 * math.sqrt(GRAVITY * FILL), domain_min=(-0.2, -0.15, -0.1), domain_max=(0.2, 0.15, 0.35),
    )
    return FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, FILL, cfg)), cfg


def test_resting_column_stays_at_rest_and_weighs_its_weight():
    fluid, cfg = _tank()
    while fluid.time < REST_SETTLE - 1e-9:
        fluid.advance(0.02)
    speed = np.linalg.norm(fluid.velocities(), axis=1).max()
    assert speed <= REST_SPEED_FRACTION * math.sqrt(GRAVITY * FILL)
    weight = fluid.n_particles * cfg.particle_volume * cfg.rest_density * GRAVITY
    assert -fluid.vessel_wrenches()[0, 2] == pytest.approx(weight, rel=hydrostatic.WEIGHT_TOLERANCE)
    assert fluid.last_report.last.active == fluid.n_particles
    assert fluid.last_report.last.volume_in_vessel[0] == pytest.approx(fluid.n_particles * cfg.particle_volume)
    hist = fluid.history()
    assert hist["density_iterations"].min() >= 1 and hist["density_iterations"].max() <= cfg.max_solver_iterations
    assert hist["density_solve_error"][-1] <= cfg.density_tolerance or hist["density_iterations"][-1] == cfg.max_solver_iterations


def test_time_step_follows_the_flow_not_the_sound_speed():
    fluid, cfg = _tank()
    wcsph, _ = _tank(PressureSolver.WCSPH)
    for f in (fluid, wcsph):
        f.advance(0.02)
        f.advance(0.02)
    acoustic = cfg.cfl * cfg.smoothing_length / cfg.sound_speed
    assert wcsph.last_report.dt <= acoustic
    # bounded by the expected flow speed instead of c0 = sound_speed_factor x that speed: about that factor longer
    assert fluid.last_report.dt >= 0.5 * cfg.sound_speed_factor * acoustic


def test_runs_are_deterministic():
    a, _ = _tank()
    b, _ = _tank()
    for f in (a, b):
        f.set_vessel_poses([Pose((0.0, 0.0, 0.0), rotation_y(0.05))])
        for _ in range(5):
            f.advance(0.004)
    assert np.array_equal(a.positions(), b.positions())
    assert np.array_equal(a.vessel_wrenches(), b.vessel_wrenches())
    assert np.array_equal(a.history()["density_iterations"], b.history()["density_iterations"])


def test_scene_selects_the_solver():
    assert FluidSettings(pressure_solver="dfsph").fluid_config(B).pressure_solver is PressureSolver.DFSPH
    assert FluidSettings().fluid_config(B).pressure_solver is PressureSolver.WCSPH


@pytest.mark.parametrize(("dim", "smoothing_ratio", "across"), [(2, 2.0, 12), (3, 1.5, 8)])
def test_wide_supports_stay_at_rest(dim, smoothing_ratio, across):
    # Supports holding many neighbours (h = 2 dx in 2-D; any 3-D lattice) make one plain Jacobi step overshoot
    # (cosim.fluid.sph_kernels.lattice_jacobi_gain above ~4). Without the relaxation these columns kept sloshing:
    # fastest particle after 1 s 0.147 m/s (2-D) and 0.317 m/s (3-D) against the bound of 0.099 (with it: 0.044 and
    # 0.074); at 40 across in 2-D (h = 2 dx) and 12 across in 3-D the columns blew up within 1 s.
    fluid, _ = _tank(across=across, dim=dim, smoothing_ratio=smoothing_ratio)
    assert fluid.model.params.jacobi_relaxation < 1.0
    while fluid.time < REST_SETTLE - 1e-9:
        fluid.advance(0.02)
    assert np.linalg.norm(fluid.velocities(), axis=1).max() <= REST_SPEED_FRACTION * math.sqrt(GRAVITY * FILL)
    assert fluid.history()["max_density_error"].max() <= hydrostatic.DENSITY_ERROR_LIMIT


def test_default_support_is_not_relaxed():
    # the 2-D default (Wendland C2, h = 1.5 dx) is within the Jacobi gain limit: its increments are not scaled
    fluid, _ = _tank()
    assert fluid.model.params.jacobi_relaxation == 1.0
