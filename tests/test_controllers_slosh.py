"""The first-mode slosh model against linear potential flow, and the paper's printed pendulum kept apart from it."""

import math

import control as ct
import numpy as np
import pytest
import scipy.integrate
import scipy.special

from controllers.errors import ControllerInputError
from controllers.slosh import (
    GRAVITY,
    J1_PRIME_FIRST_ROOT,
    SloshModel,
    VesselShape,
    first_mode_frequency,
    potential_flow_model,
    printed_paper_model,
)

PAPER_B = 0.191  # m, the paper's vessel width (= its height)
PAPER_A = 0.1591  # m, its fill depth
PAPER_L1_PENDULUM = 0.0615  # m, l1 as the paper quotes it
PAPER_B2 = -0.0027  # m, b2 = A/2 - L1 - l1 from the paper's rounded values
QUOTED_ABS_TOL = 1e-4  # m, one unit of the paper's last quoted digit (it prints l1 = 0.06145 as 0.0615)
B2_ROUNDING_TOL = 3.5e-4  # m, the rounding of the three quoted inputs of b2: 0.5e-3/2 + 0.5e-4 + 0.5e-4
PAPER_VESSEL_HINGE = 0.1155  # m, H for the paper's vessel from potential flow (rounded to 0.1 mm)
HINGE_ROUND_TOL = 5e-5  # m, that rounding
QUADRATURE_RTOL = 1e-8  # scipy quad of smooth integrands
IDENTITY_RTOL = 1e-12  # algebraic identities evaluated in float64


@pytest.fixture
def paper() -> SloshModel:
    return potential_flow_model(PAPER_B, PAPER_A)


def _box_hinge_by_quadrature(width: float, fill: float) -> float:
    """Moment about the floor centre over horizontal force of the mode pressure sin(kx) cosh(kz) on the walls and
    floor of a box (module docstring's lambda_r / lambda_x), by numerical integration."""
    k = math.pi / width
    wall = lambda z: 2.0 * math.cosh(k * z)  # both walls push the same way: p(+B/2) = -p(-B/2)
    force = scipy.integrate.quad(wall, 0.0, fill, epsabs=0, epsrel=1e-12)[0]
    wall_moment = scipy.integrate.quad(lambda z: z * wall(z), 0.0, fill, epsabs=0, epsrel=1e-12)[0]
    floor_moment = scipy.integrate.quad(lambda x: x * math.sin(k * x), -width / 2, width / 2, epsabs=0, epsrel=1e-12)[0]
    return (wall_moment + floor_moment) / force


def _cylinder_hinge_by_quadrature(diameter: float, fill: float) -> float:
    """The same for a cylinder of radius R with the mode J1(k r) cos(psi) cosh(k z), k = xi / R."""
    r = diameter / 2
    k = J1_PRIME_FIRST_ROOT / r
    j1 = scipy.special.jv(1, k * r)
    # wall: p = J1(kR) cos(psi) cosh(kz), n_x = cos(psi), dA = R dpsi dz: int cos^2 = pi
    force = math.pi * r * j1 * scipy.integrate.quad(lambda z: math.cosh(k * z), 0.0, fill, epsabs=0, epsrel=1e-12)[0]
    wall_moment = math.pi * r * j1 * scipy.integrate.quad(lambda z: z * math.cosh(k * z), 0.0, fill, epsabs=0, epsrel=1e-12)[0]
    # floor: x p over the disc, x = rho cos(psi), dA = rho drho dpsi
    floor_moment = math.pi * scipy.integrate.quad(lambda q: q * q * scipy.special.jv(1, k * q), 0.0, r, epsabs=0, epsrel=1e-12)[0]
    return (wall_moment + floor_moment) / force


def test_paper_vessel_hinge_is_115_mm_not_the_printed_64(paper: SloshModel) -> None:
    assert paper.hinge_height == pytest.approx(PAPER_VESSEL_HINGE, abs=HINGE_ROUND_TOL)
    printed = printed_paper_model(PAPER_B, PAPER_A)
    assert printed.hinge_height == pytest.approx(0.0640, abs=HINGE_ROUND_TOL)
    assert paper.b2 == pytest.approx(paper.l1 - PAPER_VESSEL_HINGE, abs=HINGE_ROUND_TOL)
    assert paper.rhp_zero < 1.1 * paper.omega1 < printed.rhp_zero  # the zero sits just above omega1, not at 61 rad/s


@pytest.mark.parametrize("fill", [0.02, 0.054, 0.1, PAPER_A, 0.19, 0.4])
def test_box_hinge_is_the_force_moment_ratio_of_the_mode(fill: float) -> None:
    model = potential_flow_model(PAPER_B, fill)
    assert model.hinge_height == pytest.approx(_box_hinge_by_quadrature(PAPER_B, fill), rel=QUADRATURE_RTOL)


@pytest.mark.parametrize("fill", [0.02, 0.06, 0.1, 0.2])
def test_cylinder_hinge_is_the_force_moment_ratio_of_the_mode(fill: float) -> None:
    diameter = 0.09
    model = potential_flow_model(diameter, fill, shape=VesselShape.CYLINDER)
    assert model.hinge_height == pytest.approx(_cylinder_hinge_by_quadrature(diameter, fill), rel=QUADRATURE_RTOL)


def test_cylinder_first_mode_uses_the_first_root_of_j1_prime() -> None:
    assert scipy.special.jvp(1, J1_PRIME_FIRST_ROOT) == pytest.approx(0.0, abs=1e-12)
    d, a = 0.09, 0.07
    k = 2 * J1_PRIME_FIRST_ROOT / d
    expected = math.sqrt(GRAVITY * k * math.tanh(k * a))
    model = potential_flow_model(d, a, shape=VesselShape.CYLINDER)
    assert model.omega1 == pytest.approx(expected, rel=IDENTITY_RTOL)
    assert 2 * math.pi * first_mode_frequency(d, a, shape=VesselShape.CYLINDER) == pytest.approx(expected, rel=IDENTITY_RTOL)


def test_deep_liquid_hinge_is_one_over_k_below_the_surface() -> None:
    for shape, k in ((VesselShape.BOX, math.pi / PAPER_B), (VesselShape.CYLINDER, 2 * J1_PRIME_FIRST_ROOT / PAPER_B)):
        model = potential_flow_model(PAPER_B, 1.5, shape=shape)  # k A > 24: tanh(kA) = 1 to 1e-20
        assert 1.5 - model.hinge_height == pytest.approx(1.0 / k, rel=1e-9)
        assert model.l1 == pytest.approx(1.0 / k, rel=1e-9)


def test_frequency_is_the_box_dispersion_relation_for_every_fill() -> None:
    for a in np.linspace(0.02, 0.19, 18):
        m = potential_flow_model(PAPER_B, float(a))
        f = math.sqrt(GRAVITY * math.pi / PAPER_B * math.tanh(math.pi * a / PAPER_B)) / (2 * math.pi)
        assert m.omega1 == pytest.approx(2 * math.pi * f, rel=IDENTITY_RTOL)
        assert first_mode_frequency(PAPER_B, float(a)) == pytest.approx(f, rel=IDENTITY_RTOL)


def test_b2_is_negative_for_every_fill_so_gp_has_a_rhp_zero() -> None:
    for a in np.linspace(0.01, 0.19, 37):
        m = potential_flow_model(PAPER_B, float(a))
        assert m.b2 < 0
        zeros = ct.zeros(m.plant())
        assert np.max(zeros.real) == pytest.approx(m.rhp_zero, rel=1e-9)


def test_printed_model_reproduces_the_papers_quoted_numbers() -> None:
    printed = printed_paper_model(PAPER_B, PAPER_A)
    assert printed.l1 == pytest.approx(PAPER_L1_PENDULUM, abs=QUOTED_ABS_TOL)
    assert printed.b2 == pytest.approx(PAPER_B2, abs=B2_ROUNDING_TOL)
    assert printed.source.startswith("paper")


def test_gp_is_eq14_with_the_physical_b2(paper: SloshModel) -> None:
    """DC gain +1 (theta1 = theta at rest), undamped poles at +-j omega1, high-frequency gain b2/l1."""
    gp = paper.plant()
    assert ct.dcgain(gp) == pytest.approx(1.0, rel=IDENTITY_RTOL)
    poles = ct.poles(gp)
    assert np.allclose(poles.real, 0.0, atol=1e-9)
    assert np.allclose(sorted(poles.imag), [-paper.omega1, paper.omega1], rtol=1e-9)
    assert abs(gp(1e6j)) == pytest.approx(abs(paper.b2 / paper.l1), rel=1e-6)
    assert ct.dcgain(ct.feedback(gp, 1)) == pytest.approx(0.5, rel=IDENTITY_RTOL)


def test_rotation_about_the_hinge_does_not_excite_the_slosh(paper: SloshModel) -> None:
    about_hinge = paper.plant(paper.hinge_height)
    w = np.logspace(-1, 3, 40)
    assert np.allclose(about_hinge(1j * w), 1.0, rtol=1e-12)


def test_forced_ratio_is_eq13(paper: SloshModel) -> None:
    g, l1, b2 = paper.gravity, paper.l1, paper.b2
    alpha = np.array([0.5, 2.0, 6.0, 11.0, 14.0, 40.0])
    eq13 = -((b2 * alpha**2 / l1) - g / l1) / (g / l1 - alpha**2)
    assert np.allclose(paper.forced_ratio(alpha), eq13, rtol=IDENTITY_RTOL)
    assert np.allclose(paper.forced_ratio(alpha), np.real(paper.plant()(1j * alpha)), rtol=1e-9)


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.3])
def test_world_pendulum_linearises_to_gp(paper: SloshModel, zeta: float) -> None:
    """state_space() (hinge driven, sigma output) with x_h = hinge_height * theta gives theta1/theta = Gp."""
    model = SloshModel(paper.l1, paper.hinge_height, zeta)
    theta1 = 1 + ct.ss2tf(model.state_space()) * model.hinge_height
    w = np.logspace(-1, 3, 50)
    assert np.allclose(theta1(1j * w), model.plant()(1j * w), rtol=1e-8)


def test_a_tilted_pivot_acts_like_pivot_height_hinge_plus_height_above_hinge(paper: SloshModel) -> None:
    """Numerical derivative of the hinge's world x against plant(p): d x_h / d theta = -(p - hinge_height)."""
    pivot, tilt, eps = (0.1005, 0.191), 0.4, 1e-7

    def hinge_x(theta: float) -> float:
        c, s = math.cos(theta), math.sin(theta)
        return -(pivot[0] * c + pivot[1] * s) + paper.hinge_height * s

    slope = (hinge_x(tilt + eps) - hinge_x(tilt - eps)) / (2 * eps)
    assert -slope == pytest.approx(paper.pivot_above_hinge(pivot, tilt), rel=1e-6)


def test_bad_parameters_name_the_field() -> None:
    with pytest.raises(ControllerInputError, match="slosh.l1"):
        SloshModel(-0.1, 0.1)
    with pytest.raises(ControllerInputError, match="slosh.damping_ratio"):
        SloshModel(0.06, 0.1, 1.5)
    with pytest.raises(ControllerInputError, match="slosh.fill_depth"):
        potential_flow_model(0.191, 0.0)
