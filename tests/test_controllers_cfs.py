"""Constant-flow stage: loop stability by pivot, the pivot rule, level drop and after-flow
(Camporredondo et al. 2019, Sec. 3.2)."""

import math

import control as ct
import numpy as np
import pytest
from scipy.integrate import quad

from controllers.cfs import after_flow_volume, cfs_pivot, crest_lever, deepest_crest_tilt, level_drop
from controllers.geometry import VesselGeometry, rotate, static_h_q, vector_step
from controllers.slosh import potential_flow_model

SEED_VESSEL = VesselGeometry()
SEED = potential_flow_model(SEED_VESSEL.inner_width, 0.1591)
K = 1.0 / 0.3  # 1/s, the default CFS time constant 0.3 s
MARGINAL_RE = 1e-6  # rad/s: |Re| below this is the marginal case (roots of O(10) rad/s in float64)
# First-order perturbation of the slosh poles by the integral law: relative error O(k / omega1) = 0.04 at k = 0.5.
PERTURBATION_RTOL = 0.05
# Trapezoid rule with 257 points on (1 - u^2)^(3/2), whose derivative is bounded: relative error < 1e-4.
QUADRATURE_RTOL = 1e-4


def _cfs_loop_poles(pivot_height: float, k: float = K) -> np.ndarray:
    """theta' = k (r - theta1), theta1 = plant(p) theta: loop (k/s) plant(p) in unity feedback."""
    return ct.poles(ct.feedback(ct.tf([k], [1.0, 0.0]) * SEED.plant(pivot_height), 1))


def test_integral_law_is_stable_about_the_lip_and_unstable_about_the_floor_centre() -> None:
    lip_height = SEED_VESSEL.lip[1]  # upright: the lip's effective height is its height L
    assert np.max(_cfs_loop_poles(lip_height).real) < 0
    assert np.max(_cfs_loop_poles(0.0).real) > 0  # the SIM pivot would pump the slosh
    assert abs(np.max(_cfs_loop_poles(SEED.hinge_height).real)) < MARGINAL_RE


def test_stability_boundary_is_the_hinge() -> None:
    """Hurwitz for l1 s^3 + k (b2 + p) s^2 + g s + k g: stable iff b2 + p > l1, i.e. p > hinge height."""
    for p in np.linspace(0.0, 0.3, 61):
        if abs(p - SEED.hinge_height) < 1e-3:
            continue
        stable = bool(np.max(_cfs_loop_poles(float(p)).real) < 0)
        assert stable == (SEED.b2 + p > SEED.l1), p


def test_margin_above_the_hinge_damps_the_slosh_at_k_m_over_2_l1() -> None:
    k = 0.5
    for margin in (0.01, 0.03, 0.06):
        poles = _cfs_loop_poles(SEED.hinge_height + margin, k)
        slosh = poles[np.argmax(np.abs(poles.imag))]
        assert -slosh.real == pytest.approx(k * margin / (2 * SEED.l1), rel=PERTURBATION_RTOL)


def test_cfs_pivot_is_the_lip_until_it_sinks_toward_the_hinge() -> None:
    margin = 0.03
    for theta in np.radians(np.arange(0.0, 90.0, 2.5)):
        pivot = cfs_pivot(SEED_VESSEL, SEED, float(theta), margin)
        above = SEED.pivot_above_hinge(SEED_VESSEL.lip, float(theta))
        if above >= margin:
            assert pivot == SEED_VESSEL.lip
        else:
            assert SEED.pivot_above_hinge(pivot, float(theta)) == pytest.approx(margin, abs=1e-12)
            lip_w = rotate(float(theta), SEED_VESSEL.lip)
            piv_w = rotate(float(theta), pivot)
            assert piv_w[0] == pytest.approx(lip_w[0], abs=1e-12)  # straight above the lip in the world
    assert SEED.pivot_above_hinge(SEED_VESSEL.lip, math.radians(50.0)) < margin  # the switch does happen


@pytest.mark.parametrize("area", [0.006, 0.003, 0.0015])  # m^2: 600, 300 and 150 mL in the 0.1 m deep vessel
def test_deepest_crest_tilt_is_where_the_liquid_at_rest_stands_highest_over_the_crest(area) -> None:
    geom = VesselGeometry(wall_thickness=0.191 / 40 * 3)
    tilt = deepest_crest_tilt(geom, area)
    assert math.radians(80.0) < tilt < math.radians(90.0)
    assert abs(crest_lever(geom, tilt, area)[0]) < 1e-9
    tilts = np.linspace(tilt - 0.05, min(tilt + 0.05, math.radians(89.99)), 101)
    heads = [static_h_q(geom, float(t), area) for t in tilts]
    assert static_h_q(geom, tilt, area) >= max(heads) - 1e-6  # within a micrometre of the largest head nearby


def test_level_drop_of_a_level_surface_spanning_the_vessel() -> None:
    area, theta, volume = SEED_VESSEL.inner_width * 0.12, 0.4, 2e-6
    chord = SEED_VESSEL.inner_width / math.cos(theta)
    assert level_drop(SEED_VESSEL, theta, area, volume) == pytest.approx(volume / (SEED_VESSEL.inner_depth * chord))


def test_after_flow_in_the_acceleration_phase() -> None:
    """Short stop, accel phase only: rise ~ t^2, so the volume is Q T 3 pi / 16 with T = sqrt(2 angle / a)."""
    q, h_q, accel = 6e-5, 0.005, 1.5
    lever = crest_lever(SEED_VESSEL, 0.4, SEED_VESSEL.inner_width * 0.15)
    angle = -vector_step(lever, -h_q)
    t_stop = math.sqrt(2 * angle / accel)
    expected = q * t_stop * 3 * math.pi / 16
    assert after_flow_volume(q, h_q, lever, max_rate=10.0, max_accel=accel) == pytest.approx(expected, rel=QUADRATURE_RTOL)
    assert after_flow_volume(q, -0.001, lever, 10.0, accel) == 0.0


def test_after_flow_of_a_return_that_first_brakes_a_forward_tilt() -> None:
    """Started while tilting forward at w0: back(t) = -w0 t + a t^2 / 2 (rate limit not reached), so the volume is
    Q times the integral of (1 - back / angle)^(3/2) up to back = angle (by adaptive quadrature here)."""
    q, h_q, accel, w0 = 6e-5, 0.005, 1.5, 0.3
    lever = crest_lever(SEED_VESSEL, 0.4, SEED_VESSEL.inner_width * 0.15)
    angle = -vector_step(lever, -h_q)
    t_end = (w0 + math.sqrt(w0 * w0 + 2 * accel * angle)) / accel
    expected, _ = quad(lambda t: (1.0 + (w0 * t - 0.5 * accel * t * t) / angle) ** 1.5, 0.0, t_end)
    got = after_flow_volume(q, h_q, lever, max_rate=10.0, max_accel=accel, tilt_rate=w0)
    assert got == pytest.approx(q * expected, rel=QUADRATURE_RTOL)
    assert got > after_flow_volume(q, h_q, lever, 10.0, accel)  # braking first lets more out


def test_after_flow_of_a_vessel_that_lags_its_command() -> None:
    """A vessel ``lag`` s behind its command keeps pouring at the current rate for that long, then returns."""
    q, h_q, accel, w0, lag = 6e-5, 0.005, 1.5, 0.3, 0.08
    lever = crest_lever(SEED_VESSEL, 0.4, SEED_VESSEL.inner_width * 0.15)
    prompt = after_flow_volume(q, h_q, lever, 1.0, accel, w0)
    assert after_flow_volume(q, h_q, lever, 1.0, accel, w0, lag) == pytest.approx(prompt + q * lag, rel=1e-12)
    assert after_flow_volume(q, -0.001, lever, 1.0, accel, w0, lag) == 0.0  # nothing over the crest


