"""The artificial viscosity's velocity scale (``fluid.artificial_viscosity_scale``), the one alpha
(``fluid.free_artificial_viscosity`` unset) and the time step's artificial-viscosity criterion."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
import warp as wp

from cosim.cli.main import main
from cosim.errors import InputError
from cosim.fluid.config import (
    DEFAULT_ARTIFICIAL_VISCOSITY, DEFAULT_DENSITY_TOLERANCE, GRAVITY, SOUND_SPEED_FREE_ARTIFICIAL_VISCOSITY, WCSPH_ARTIFICIAL_VISCOSITY_BETA,
    ArtificialViscosityScale, DensityIteration, FluidConfig,
)
from cosim.fluid.params import SPHParams, make_params
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.fluid.sph_common import kernel_gradient, viscous_pair
from cosim.fluid.time_step import FORCE_CFL, VISCOUS_CFL, artificial_kinematic_viscosity, stable_time_step
from cosim.frames import Pose
from cosim.vessel import VesselSpec

SPACING = 0.005  # m
DISTANCE = 0.006  # m, the pair's separation (inside the support 2h = 0.015 m)


@wp.kernel
def _pair_acceleration(prm: SPHParams, r: wp.vec3, v_rel: wp.vec3, out: wp.array(dtype=wp.vec3)):
    gw = kernel_gradient(prm, r, wp.dot(r, r))
    out[0] = viscous_pair(prm, prm.alpha, prm.mass, r, wp.dot(r, r), gw, v_rel, v_rel, prm.rest_density, prm.rest_density)
    out[1] = gw


def _pair(cfg: FluidConfig, closing_speed: float) -> tuple[np.ndarray, np.ndarray]:
    """(acceleration of i, grad_i W) for particle i at +DISTANCE along x from j, closing on it at ``closing_speed``
    (m/s; negative: receding), both at rest density."""
    out = wp.zeros(2, dtype=wp.vec3, device="cpu")
    wp.launch(_pair_acceleration, 1, inputs=[make_params(cfg, 0), wp.vec3(DISTANCE, 0.0, 0.0), wp.vec3(-closing_speed, 0.0, 0.0), out],
              device="cpu")
    a, gw = out.numpy()
    return a, gw


def _config(**kw) -> FluidConfig:
    return FluidConfig(dim=2, spacing=SPACING, kinematic_viscosity=0.0, artificial_viscosity=0.5, **kw)


def _monaghan(cfg: FluidConfig, closing_speed: float, scale: float, gw: np.ndarray) -> np.ndarray:
    """m_j alpha c mu / rho0 grad W, mu = h v_rel . r / (r^2 + 0.01 h^2), with the velocity scale c = ``scale``."""
    h = cfg.smoothing_length
    mu = h * (-closing_speed * DISTANCE) / (DISTANCE**2 + 0.01 * h * h)
    return cfg.particle_mass * cfg.alpha * scale * mu / cfg.rest_density * gw


@pytest.mark.parametrize("closing_speed", [0.1, 1.0])
def test_dfsph_signal_velocity_is_the_gravity_wave_speed_plus_twice_the_approach_speed(closing_speed):
    cfg = _config(artificial_viscosity_scale="signal_velocity")
    a, gw = _pair(cfg, closing_speed)
    signal = math.sqrt(GRAVITY * cfg.smoothing_length) + 2.0 * closing_speed
    np.testing.assert_allclose(a, _monaghan(cfg, closing_speed, signal, gw), rtol=1e-5, atol=0.0)
    assert a[0] > 0.0  # pushed away from j: the approach is decelerated


def test_the_sound_speed_scale_is_c0_and_wcsph_keeps_it_with_either_setting():
    # DFSPH's 'sound_speed': c0 alone; WCSPH: c0 under either setting, plus its default quadratic term beta w
    # (Monaghan 1992's beta = 2; alpha (c0 + (beta / alpha) w), w the closing speed along r)
    closing_speed = 0.3
    dfsph = _config(artificial_viscosity_scale="sound_speed")
    a, gw = _pair(dfsph, closing_speed)
    np.testing.assert_allclose(a, _monaghan(dfsph, closing_speed, dfsph.sound_speed, gw), rtol=1e-5, atol=0.0)
    for cfg in (_config(pressure_solver="wcsph"), _config(pressure_solver="wcsph", artificial_viscosity_scale="signal_velocity")):
        assert cfg.quadratic_viscosity == WCSPH_ARTIFICIAL_VISCOSITY_BETA == 2.0
        a, gw = _pair(cfg, closing_speed)
        scale = cfg.sound_speed + WCSPH_ARTIFICIAL_VISCOSITY_BETA / cfg.alpha * closing_speed
        np.testing.assert_allclose(a, _monaghan(cfg, closing_speed, scale, gw), rtol=1e-5, atol=0.0)


def test_a_receding_pair_feels_no_artificial_viscosity():
    for scale in ("sound_speed", "signal_velocity"):
        a, _ = _pair(_config(artificial_viscosity_scale=scale), -1.0)
        assert np.all(a == 0.0)


def test_an_unset_free_alpha_is_the_one_alpha_under_the_signal_velocity_and_wcsph_and_its_own_under_dfsphs_c0():
    assert _config(free_artificial_viscosity=None).free_liquid_alpha == 0.5
    assert make_params(_config(free_artificial_viscosity=None), 0).alpha_free == 0.5
    assert make_params(_config(free_artificial_viscosity=0.25), 0).alpha_free == 0.25
    assert make_params(_config(pressure_solver="wcsph"), 0).alpha_free == 0.5
    assert _config(artificial_viscosity_scale="sound_speed").free_liquid_alpha == SOUND_SPEED_FREE_ARTIFICIAL_VISCOSITY


def test_wcsphs_quadratic_term_needs_its_one_alpha():
    # the kernel scales the approach term with each pair's alpha: a free-liquid alpha of its own (the former WCSPH
    # default, 0.25), an alpha of 0 or no free liquid's rule decide whether the default beta applies
    assert FluidConfig(pressure_solver="wcsph").quadratic_viscosity == WCSPH_ARTIFICIAL_VISCOSITY_BETA
    assert FluidConfig(pressure_solver="wcsph").viscosity_approach_weight == WCSPH_ARTIFICIAL_VISCOSITY_BETA / 0.01
    assert FluidConfig(pressure_solver="wcsph", free_artificial_viscosity=0.25).quadratic_viscosity is None
    assert FluidConfig(pressure_solver="wcsph", free_artificial_viscosity=0.25).viscosity_approach_weight == 0.0
    assert FluidConfig(pressure_solver="wcsph", artificial_viscosity=0.0).quadratic_viscosity is None
    assert FluidConfig(pressure_solver="wcsph", free_liquid=False, free_artificial_viscosity=0.25).quadratic_viscosity == 2.0
    assert FluidConfig(pressure_solver="wcsph", artificial_viscosity_beta=1.0).quadratic_viscosity == 1.0
    assert FluidConfig(artificial_viscosity_scale="sound_speed").quadratic_viscosity is None  # DFSPH's c0: none


def test_an_unset_alpha_is_the_velocity_scales_own():
    signal = DEFAULT_ARTIFICIAL_VISCOSITY[ArtificialViscosityScale.SIGNAL_VELOCITY]
    assert FluidConfig().alpha == signal
    assert FluidConfig(artificial_viscosity_scale="sound_speed").alpha == DEFAULT_ARTIFICIAL_VISCOSITY[ArtificialViscosityScale.SOUND_SPEED]
    assert FluidConfig(artificial_viscosity_scale="signal_velocity").alpha == signal
    assert FluidConfig(artificial_viscosity_scale="signal_velocity", pressure_solver="wcsph").alpha == 0.01  # c0
    # unset stays unset, so a replaced solver or iteration resolves for itself
    assert replace(FluidConfig(), pressure_solver="wcsph").alpha == 0.01
    assert replace(FluidConfig(), density_iteration="jacobi").density_solve_tolerance == DEFAULT_DENSITY_TOLERANCE[DensityIteration.JACOBI]


def _cfl_and_force_step(cfg: FluidConfig, flow_speed: float, max_accel: float) -> float:
    h = cfg.smoothing_length
    return min(cfg.cfl * h / flow_speed, FORCE_CFL * math.sqrt(h / max_accel))


def test_the_viscous_criterion_leaves_the_c0_scaled_step_alone():
    # alpha 0.25 c0 (c0 = 10 v): dt_visc = 0.4 h / v against the CFL's 0.25 h / v
    cfg = FluidConfig(dim=2, spacing=SPACING, max_expected_speed=1.0, artificial_viscosity_scale="sound_speed")
    assert stable_time_step(cfg, 0.0, 1.5, 10.0) == _cfl_and_force_step(cfg, 1.5, 10.0)


@pytest.mark.parametrize("scale, free_alpha", [("signal_velocity", None), ("sound_speed", 0.25)])
def test_the_viscous_criterion_binds_past_the_diffusion_limit(scale, free_alpha):
    # at the largest Courant number the artificial viscosity's diffusion limit 0.125 h^2 / nu_art is the shorter
    # (v the expected speed, reached): the signal velocity with alpha 1, nu_art = alpha h (sqrt(g h) + 2 (2 v)) / 8,
    # dt just under 0.25 h / v; c0 = 10 v with the free alpha 0.25, nu_art = 0.25 h (10 v) / 8, dt = 0.4 h / v; the
    # CFL's is 0.6 h / v
    cfg = FluidConfig(dim=2, spacing=SPACING, max_expected_speed=1.0, cfl=0.6, artificial_viscosity=1.0 if free_alpha is None else 0.01,
                      artificial_viscosity_scale=scale, free_artificial_viscosity=free_alpha)
    h, speed = cfg.smoothing_length, cfg.max_expected_speed
    nu_art = artificial_kinematic_viscosity(cfg, speed, 0.0)
    expected_scale = math.sqrt(GRAVITY * h) + 4.0 * speed if free_alpha is None else cfg.sound_speed
    assert nu_art == pytest.approx((1.0 if free_alpha is None else 0.25) * h * expected_scale / 8.0, rel=1e-12)
    dt = stable_time_step(cfg, 0.0, speed, 1e-3)
    assert dt == pytest.approx(VISCOUS_CFL * h * h / (cfg.kinematic_viscosity + nu_art), rel=1e-12)
    assert dt < 0.7 * _cfl_and_force_step(cfg, speed, 1e-3)


def test_wall_speed_raises_the_approach_speed_the_criterion_plans_with():
    cfg = FluidConfig(dim=3, spacing=SPACING, artificial_viscosity=1.0, artificial_viscosity_scale="signal_velocity")
    h, c = cfg.smoothing_length, math.sqrt(GRAVITY * cfg.smoothing_length)
    assert artificial_kinematic_viscosity(cfg, 1.0, 0.5) == pytest.approx(h * (c + 2.0 * 2.0) / 10.0)
    assert artificial_kinematic_viscosity(cfg, 1.0, 3.0) == pytest.approx(h * (c + 2.0 * 4.0) / 10.0)


def _wcsph_tank_after_a_pulse(scale: str) -> np.ndarray:
    """Positions of a small WCSPH tank's liquid after a sideways jerk of the tank (approaching pairs at the walls)."""
    cfg = FluidConfig(dim=2, spacing=0.01, pressure_solver="wcsph", max_expected_speed=1.0, artificial_viscosity_scale=scale,
                      domain_min=(-0.2, -0.1, -0.05), domain_max=(0.2, 0.1, 0.25))
    tank = VesselSpec(name="tank", inner_width=0.1, inner_depth=0.1, inner_height=0.12)
    solver = FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, 0.06, cfg))
    for k in range(4):
        solver.set_vessel_poses([Pose((0.002 * (k + 1), 0.0, 0.0))])
        solver.advance(0.005)
    return solver.positions()


def test_wcsph_runs_bit_identical_with_either_scale():
    assert np.array_equal(_wcsph_tank_after_a_pulse("sound_speed"), _wcsph_tank_after_a_pulse("signal_velocity"))


def test_the_validation_cases_take_the_viscosity_settings(capsys):
    argv = ["validate", "hydrostatic", "--spacing", "0.0125", "--width", "0.1", "--fill", "0.05", "--no-plot", "--json"]
    assert main(argv) == 0
    default = json.loads(capsys.readouterr().out)["cases"][0]
    assert main([*argv, "--artificial-viscosity-scale", "sound_speed", "--free-artificial-viscosity", "0.25"]) == 0
    sound_speed = json.loads(capsys.readouterr().out)["cases"][0]
    assert sound_speed["pressure"] != default["pressure"]


@pytest.mark.parametrize("flag, value", [("--free-artificial-viscosity", "abc"), ("--free-artificial-viscosity", "2"),
                                         ("--artificial-viscosity", "-1")])
def test_bad_viscosity_input_exits_2_with_one_line(flag, value, capsys):
    assert main(["validate", "hydrostatic", flag, value, "--no-plot"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("cosim validate: error:")


# ---- Monaghan's quadratic coefficient beta (fluid.artificial_viscosity_beta)

def _beta_config(beta: float | None, **kw) -> FluidConfig:
    """WCSPH with one alpha (0.5 for the bulk and the free liquid alike) and Monaghan's beta."""
    return _config(pressure_solver="wcsph", free_artificial_viscosity=0.5, artificial_viscosity_beta=beta, **kw)


def test_beta_is_the_approach_terms_coefficient_on_top_of_c0():
    # Pi = -(alpha c0 + beta w) mu / rho: the kernel's alpha (c + b w) with b = beta / alpha
    cfg = _beta_config(2.0)
    assert cfg.viscosity_speed == cfg.sound_speed
    assert cfg.viscosity_approach_weight == pytest.approx(2.0 / 0.5)
    assert make_params(cfg, 0).viscosity_approach_weight == pytest.approx(4.0)
    for closing_speed in (0.1, 1.0):
        a, gw = _pair(cfg, closing_speed)
        np.testing.assert_allclose(a, _monaghan(cfg, closing_speed, cfg.sound_speed + (2.0 / 0.5) * closing_speed, gw), rtol=1e-5, atol=0.0)
    a_receding, _ = _pair(cfg, -1.0)
    assert np.all(a_receding == 0.0)


def test_an_unset_beta_is_each_scales_own():
    assert _beta_config(None).viscosity_approach_weight == pytest.approx(WCSPH_ARTIFICIAL_VISCOSITY_BETA / 0.5)  # WCSPH's beta 2
    assert _beta_config(0.0).viscosity_approach_weight == 0.0  # c0 alone, as set
    assert _config(artificial_viscosity_scale="sound_speed").viscosity_approach_weight == 0.0  # DFSPH's c0: no approach term
    assert _config(artificial_viscosity_scale="signal_velocity").viscosity_approach_weight == 2.0  # Monaghan (1997)'s
    # with the signal velocity beta replaces its 2 alpha: alpha 0.5, beta 2 -> b = 4 on sqrt(g h)
    signal = _config(artificial_viscosity_scale="signal_velocity", artificial_viscosity_beta=2.0)
    assert signal.viscosity_approach_weight == pytest.approx(4.0)
    assert signal.viscosity_speed == pytest.approx(math.sqrt(GRAVITY * signal.smoothing_length))


def test_the_viscous_criterion_takes_beta_at_the_planned_approach():
    # nu_art = h (alpha c0 + beta w) / 8, w = 2 v (two particles head on at the planned flow speed v)
    cfg = FluidConfig(dim=2, spacing=SPACING, pressure_solver="wcsph", max_expected_speed=1.0, artificial_viscosity=0.01,
                      free_artificial_viscosity=0.01, artificial_viscosity_beta=2.0)
    h, v = cfg.smoothing_length, 1.5
    assert artificial_kinematic_viscosity(cfg, v, 0.0) == pytest.approx(h * (0.01 * cfg.sound_speed + 2.0 * 2.0 * v) / 8.0, rel=1e-12)
    limits_dt = stable_time_step(cfg, 0.0, v, 1e-3)
    viscous = VISCOUS_CFL * h * h / (cfg.kinematic_viscosity + artificial_kinematic_viscosity(cfg, v, 0.0))
    acoustic = cfg.cfl * h / (cfg.sound_speed + v)
    assert limits_dt == pytest.approx(min(viscous, acoustic), rel=1e-12)
    # c0 = 10 v: beta 2 leaves WCSPH's step to the CFL condition (dt_visc = h / (alpha c0 + 4 beta v) ~ 0.12 h / v
    # against 0.6 h / (11 v) = 0.055 h / v at the largest Courant number); the top of beta's range, 10, binds it
    # (~0.025 h / v)
    for beta, binds in ((2.0, False), (10.0, True)):
        fast = replace(cfg, cfl=0.6, artificial_viscosity_beta=beta)
        viscous = VISCOUS_CFL * h * h / (fast.kinematic_viscosity + artificial_kinematic_viscosity(fast, 1.0, 0.0))
        acoustic = fast.cfl * h / (fast.sound_speed + 1.0)
        assert stable_time_step(fast, 0.0, 1.0, 1e-3) == pytest.approx(viscous if binds else acoustic, rel=1e-12)
        assert (viscous < acoustic) is binds


@pytest.mark.parametrize("kw, message", [
    ({"artificial_viscosity_beta": 2.0, "free_artificial_viscosity": 0.25}, "needs one alpha for all liquid"),  # 0.25 against 0.01
    ({"artificial_viscosity_beta": 2.0, "free_artificial_viscosity": 0.0, "artificial_viscosity": 0.0}, "needs Monaghan's alpha above 0"),
    ({"artificial_viscosity_beta": -1.0, "free_artificial_viscosity": 0.01}, "fluid.artificial_viscosity_beta"),
    ({"artificial_viscosity_beta": 11.0, "free_artificial_viscosity": 0.01}, "fluid.artificial_viscosity_beta"),
])
def test_bad_beta_is_refused_with_what_to_do(kw, message):
    with pytest.raises(InputError, match=message):
        FluidConfig(pressure_solver="wcsph", **kw)


def test_beta_goes_without_one_alpha_where_no_liquid_is_free():
    cfg = FluidConfig(pressure_solver="wcsph", free_liquid=False, artificial_viscosity_beta=2.0)
    assert cfg.viscosity_approach_weight == pytest.approx(200.0)


def test_the_validation_cases_take_beta(capsys):
    argv = ["validate", "hydrostatic", "--solver", "wcsph", "--spacing", "0.0125", "--width", "0.1", "--fill", "0.05", "--no-plot", "--json"]
    assert main([*argv, "--artificial-viscosity-beta", "0"]) == 0
    without_beta = json.loads(capsys.readouterr().out)["cases"][0]
    assert main(argv) == 0
    with_beta = json.loads(capsys.readouterr().out)["cases"][0]  # WCSPH's default, beta 2
    assert with_beta["pressure"] != without_beta["pressure"]  # the settling column's approaching pairs feel beta
    # beta with a free-liquid alpha of its own: refused as bad input, one line
    assert main(["validate", "hydrostatic", "--solver", "wcsph", "--artificial-viscosity-beta", "2", "--free-artificial-viscosity", "0.25",
                 "--no-plot"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "needs one alpha for all liquid" in err[0]
