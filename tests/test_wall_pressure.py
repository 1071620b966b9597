"""How DFSPH's walls carry pressure (``FluidConfig.wall_pressure``): 'solved_rest_sum' holds each wall particle of a
thin wall to the summation density it has with liquid resting against it, so thin walls carry a resting column;
'mirrored' puts no unknown on the wall; where the walls cover the kernel support, 'solved_rest_sum' is
'solved_layer' to the bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.fluid.config import GRAVITY, FluidConfig, WallModel, WallPressure
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.fluid.wall_sampling import sample_vessel_walls, wall_rest_offsets, wetted_layer
from cosim.frames import Pose
from cosim.validation import hydrostatic
from cosim.vessel import VesselSpec

B = 0.191  # m, the pouring vessel's inner width (Camporredondo et al. 2019); its walls are 5 mm thick
FILL = 0.1  # m
TANK = VesselSpec(name="tank", inner_width=B, inner_depth=0.1, inner_height=0.2)
# A thin wall's rest sum, as the numpy fit computes it, against the solver's own float32 summation density of the
# wall layer (kg/m^3 over rho0)
REST_SUM_RTOL = 1e-3
# The resting column against thin walls (20 across): after REST_SETTLE the fastest particle is slower than this
# fraction of the shallow-water wave speed sqrt(g H), the bound tests/test_fluid_dfsph.py holds the default walls to
# after 1 s; against thin walls the start-up motion takes longer to die down (0.12 after 1 s, 0.04 after 2 s).
REST_SPEED_FRACTION = 0.1
REST_SETTLE = 2.0  # s


def _config(across: int, wall_model: WallModel, wall_pressure: WallPressure) -> FluidConfig:
    return FluidConfig(
        dim=2, spacing=B / across, max_expected_speed=2 * math.sqrt(GRAVITY * FILL), domain_min=(-0.2, -0.15, -0.1),
        domain_max=(0.2, 0.15, 0.35), wall_model=wall_model, wall_pressure=wall_pressure,
    )


def _column(across: int, wall_model: WallModel, wall_pressure: WallPressure, fill: float = FILL) -> tuple[FluidSolver, FluidConfig]:
    cfg = _config(across, wall_model, wall_pressure)
    return FluidSolver(cfg, [TANK], [Pose()], fill_vessel(TANK, fill, cfg)), cfg


def _rest(fluid: FluidSolver, duration: float) -> None:
    while fluid.time < duration - 1e-9:
        fluid.advance(0.02)


def test_walls_covering_the_support_need_no_rest_offset():
    cfg = _config(20, WallModel.KERNEL_LAYERS, WallPressure.SOLVED_REST_SUM)
    points, volumes = sample_vessel_walls(TANK, cfg)
    assert not wall_rest_offsets(TANK, cfg, points, volumes).any()


def test_a_thin_wall_layer_sums_to_rho0_with_liquid_at_rest_against_it():
    """The offsets are large (a thin wall's own sum is far short of rho0: 0.149-0.374 rho0 here), and with them the
    solver's summation density of the wetted layer is rho0 wherever the resting liquid fills its kernel support as
    it fills the tank's to the rim (the rest sums' reference), after a substep or two."""
    fluid, cfg = _column(20, WallModel.REAL_THICKNESS, WallPressure.SOLVED_REST_SUM)
    fluid.advance(0.002)
    wetted = fluid.model.b_wetted.numpy().astype(bool)
    assert wetted.sum() == wetted_layer(TANK, sample_vessel_walls(TANK, cfg)[0], cfg.spacing, 2).sum()
    assert fluid.model.b_rest_offset.numpy()[wetted].min() > 0.1 * cfg.rest_density
    z = fluid.model.b_local.numpy()[:, 2]
    rho = fluid.step.scratch.b_rho.numpy() / cfg.rest_density
    covered = wetted & (z < FILL - cfg.support_radius)
    assert covered.sum() > 20
    np.testing.assert_allclose(rho[covered], 1.0, rtol=REST_SUM_RTOL)


def test_thin_walls_held_to_their_rest_sums_carry_a_resting_column():
    fluid, cfg = _column(20, WallModel.REAL_THICKNESS, WallPressure.SOLVED_REST_SUM)
    _rest(fluid, REST_SETTLE)
    weight = fluid.n_particles * cfg.particle_volume * cfg.rest_density * GRAVITY
    assert -fluid.vessel_wrenches()[0, 2] == pytest.approx(weight, rel=hydrostatic.WEIGHT_TOLERANCE)
    assert np.linalg.norm(fluid.velocities(), axis=1).max() <= REST_SPEED_FRACTION * math.sqrt(GRAVITY * FILL)
    assert fluid.last_report.last.volume_in_vessel[0] == pytest.approx(fluid.n_particles * cfg.particle_volume)


def test_rest_sums_change_nothing_where_the_walls_cover_the_support():
    runs = []
    for pressure in (WallPressure.SOLVED_LAYER, WallPressure.SOLVED_REST_SUM):
        fluid, _ = _column(12, WallModel.KERNEL_LAYERS, pressure)
        _rest(fluid, 0.1)
        runs.append((fluid.positions(), fluid.velocities(), fluid.pressures(), fluid.vessel_wrenches()))
    for solved, rest_sum in zip(*runs):
        np.testing.assert_array_equal(solved, rest_sum)


def test_mirrored_walls_carry_a_resting_column_with_no_wall_unknown():
    fluid, cfg = _column(12, WallModel.KERNEL_LAYERS, WallPressure.MIRRORED)
    _rest(fluid, 1.0)
    weight = fluid.n_particles * cfg.particle_volume * cfg.rest_density * GRAVITY
    assert -fluid.vessel_wrenches()[0, 2] == pytest.approx(weight, rel=hydrostatic.WEIGHT_TOLERANCE)
    scratch = fluid.step.scratch
    assert not scratch.b_kappa_density.numpy().any() and not scratch.b_kappa_divergence.numpy().any()


def test_a_thin_walls_rim_is_offset_for_the_wall_it_lacks_not_for_liquid_above_it():
    """The offset makes up the layers a thin wall lacks behind it; the rim's particles also lack liquid above them
    (the vessel holds none above its rim), which liquid flowing over the crest supplies: offset for that too, the
    crest would push the flowing liquid off as if it were a step. So the rim's particle is offset no more than the
    wall's particles below it, which have the same layers missing."""
    cfg = _config(20, WallModel.REAL_THICKNESS, WallPressure.SOLVED_REST_SUM)
    points, volumes = sample_vessel_walls(TANK, cfg)
    offsets = wall_rest_offsets(TANK, cfg, points, volumes)
    side = points[:, 0] > 0.5 * TANK.inner_width
    rim = side & (points[:, 2] == points[side, 2].max())
    below = side & (points[:, 2] > cfg.support_radius) & (points[:, 2] < TANK.inner_height - cfg.support_radius)
    assert below.sum() > 5
    assert offsets[rim].max() <= offsets[below].min() + 1e-3 * cfg.rest_density
