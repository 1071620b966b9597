"""Slosh pendulum model against the seed's and the reference README's numbers (seed Eqs. 10-14, 17)."""

import math

import control as ct
import numpy as np
import pytest

from controllers.slosh import GRAVITY, SloshModel, first_mode_frequency

SEED_B = 0.191  # m, seed vessel width = height (seed Sec. 4; reference README)
SEED_A = 0.1591  # m, seed fill depth
SEED_L1_PENDULUM = 0.0615  # m, l1 quoted by the seed (Sec. 3.1) and the reference README
SEED_L1_HINGE = 0.0207  # m, L1 quoted by the seed (Sec. 3.1)
SEED_B2 = -0.0027  # m, b2 = A/2 - L1 - l1 from the seed's rounded values (reference README)
# The seed quotes 3 significant digits. The model gives l1 = 0.061449 m, which the seed prints as 0.0615 (it
# rounds 0.06145 half-up, a double rounding), so the tolerance is one unit of the last quoted digit.
QUOTED_ABS_TOL = 1e-4  # m
# b2 from the seed's own rounded A, L1, l1 (0.159, 0.0207, 0.0615) differs from the unrounded value by the
# rounding of those three inputs: |0.5e-3/2| + 0.5e-4 + 0.5e-4 = 3.5e-4 m.
B2_ROUNDING_TOL = 3.5e-4  # m
IDENTITY_RTOL = 1e-12  # algebraic identities evaluated in float64


@pytest.fixture
def seed() -> SloshModel:
    return SloshModel(SEED_B, SEED_A)


def test_pendulum_parameters_match_the_seed(seed: SloshModel) -> None:
    assert seed.l1 == pytest.approx(SEED_L1_PENDULUM, abs=QUOTED_ABS_TOL)
    assert seed.L1 == pytest.approx(SEED_L1_HINGE, abs=QUOTED_ABS_TOL)
    assert seed.b2 == pytest.approx(SEED_B2, abs=B2_ROUNDING_TOL)
    assert 0.159 / 2 - 0.0207 - 0.0615 == pytest.approx(SEED_B2, abs=1e-12)  # the reference's own arithmetic


def test_eq17_equals_the_pendulum_frequency(seed: SloshModel) -> None:
    """omega1^2 = g / l1 reproduces Eq. 17 (reference README: 'when L = B'), for every fill."""
    for a in np.linspace(0.02, 0.19, 18):
        m = SloshModel(SEED_B, float(a))
        f17 = first_mode_frequency(SEED_B, float(a))
        assert m.omega1 == pytest.approx(2 * math.pi * f17, rel=IDENTITY_RTOL)
    expected = math.sqrt(GRAVITY * math.pi / SEED_B * math.tanh(math.pi * SEED_A / SEED_B)) / (2 * math.pi)
    assert first_mode_frequency(SEED_B, SEED_A) == pytest.approx(expected, rel=IDENTITY_RTOL)


def test_b2_is_negative_for_every_fill_so_gp_has_a_rhp_zero() -> None:
    for a in np.linspace(0.01, 0.19, 37):
        m = SloshModel(SEED_B, float(a))
        closed_form = -(4 * SEED_B / math.pi) / math.sinh(2 * math.pi * a / SEED_B)
        assert m.b2 == pytest.approx(closed_form, rel=1e-9)
        assert m.b2 < 0
        zeros = ct.zeros(m.plant())
        assert np.max(zeros.real) == pytest.approx(m.rhp_zero, rel=1e-9)
        assert m.rhp_zero > 0


def test_gp_is_the_printed_eq14(seed: SloshModel) -> None:
    """DC gain +1 (theta1 = theta at rest), undamped poles at +-j omega1, high-frequency gain b2/l1."""
    gp = seed.plant()
    assert ct.dcgain(gp) == pytest.approx(1.0, rel=IDENTITY_RTOL)
    poles = ct.poles(gp)
    assert np.allclose(poles.real, 0.0, atol=1e-9)
    assert np.allclose(sorted(poles.imag), [-seed.omega1, seed.omega1], rtol=1e-9)
    assert abs(gp(1e6j)) == pytest.approx(abs(seed.b2 / seed.l1), rel=1e-6)
    # Unity feedback without a compensator: DC gain 1/2, the seed's "steady-state error of one half".
    assert ct.dcgain(ct.feedback(gp, 1)) == pytest.approx(0.5, rel=IDENTITY_RTOL)


def test_forced_ratio_is_eq13(seed: SloshModel) -> None:
    """Eq. 13 (written for theta_n = -theta1): theta1/phi = -[b2 a^2/l1 - g/l1] / (g/l1 - a^2)."""
    g, l1, b2 = seed.gravity, seed.l1, seed.b2
    alpha = np.array([0.5, 2.0, 6.0, 11.0, 14.0, 40.0])
    eq13 = -((b2 * alpha**2 / l1) - g / l1) / (g / l1 - alpha**2)
    assert np.allclose(seed.forced_ratio(alpha), eq13, rtol=IDENTITY_RTOL)
    assert np.allclose(seed.forced_ratio(alpha), np.real(seed.plant()(1j * alpha)), rtol=1e-9)


def test_world_pendulum_linearises_to_gp(seed: SloshModel) -> None:
    """state_space() (hinge driven, sigma output) with x_h = hinge_height * theta gives theta1/theta = Gp."""
    sigma_per_xh = ct.ss2tf(seed.state_space())
    theta1 = 1 + sigma_per_xh * seed.hinge_height
    w = np.logspace(-1, 3, 50)
    assert np.allclose(theta1(1j * w), seed.plant()(1j * w), rtol=1e-8)


def test_a_tilted_pivot_acts_like_pivot_height_hinge_plus_height_above_hinge(seed: SloshModel) -> None:
    """Numerical derivative of the hinge's world x against plant(p): d x_h / d theta = -(p - hinge_height)."""
    pivot, tilt, eps = (0.1005, 0.191), 0.4, 1e-7

    def hinge_x(theta: float) -> float:
        # origin moves so that the pivot stays fixed: x_O = -R(theta) pivot; hinge = x_O + R(theta) (0, z_P)
        c, s = math.cos(theta), math.sin(theta)
        return -(pivot[0] * c + pivot[1] * s) + seed.hinge_height * s

    slope = (hinge_x(tilt + eps) - hinge_x(tilt - eps)) / (2 * eps)
    assert -slope == pytest.approx(seed.pivot_above_hinge(pivot, tilt), rel=1e-6)
