"""Planar poses, the static liquid in a tilted box (Camporredondo et al. 2019, Eq. 16) and the CFS
vector step (its Fig. 9)."""

import math

import numpy as np
import pytest

from controllers.cfs import crest_lever
from controllers.geometry import (
    PlanarPose,
    VesselGeometry,
    eq16_tilt,
    height_above,
    rotate,
    static_h_q,
    static_tilt_for_h_q,
    surface_chord,
    surface_offset,
    vector_step,
)

SEED = VesselGeometry()  # B = L = 0.191 m, t = 5 mm (the paper's vessel, its Sec. 4)
EXACT = 1e-12  # m or rad: identities that hold to float64 round-off on O(0.1) quantities
# m^2: trapezoid rule with 200001 samples on a piecewise-linear integrand; the only error is at the kink where
# the line meets the floor, (step^2 / 4) * slope ~ 1e-11 m^2 for slope 6.
AREA_QUADRATURE_TOL = 1e-10


def test_rotation_sign_lowers_the_lip() -> None:
    x, z = rotate(0.3, SEED.lip)
    assert z < SEED.lip[1]  # theta > 0 lowers the +x lip (R_y convention)
    assert (x, z) == pytest.approx((SEED.lip[0] * math.cos(0.3) + SEED.lip[1] * math.sin(0.3),
                                    -SEED.lip[0] * math.sin(0.3) + SEED.lip[1] * math.cos(0.3)), abs=EXACT)


def test_rotating_about_a_pivot_keeps_it_fixed_and_the_pose_continuous() -> None:
    pose = PlanarPose(0.01, -0.02, 0.2)
    for pivot in [(0.0, 0.0), SEED.lip, (0.0, 0.064), (-0.05, 0.3)]:
        new = pose.rotated_about(pivot, 0.35)
        assert new.theta == 0.35
        assert new.point(pivot) == pytest.approx(pose.point(pivot), abs=EXACT)
        same = pose.rotated_about(pivot, pose.theta)  # zero rotation: no jump when the pivot changes
        assert (same.dx, same.dz) == pytest.approx((pose.dx, pose.dz), abs=EXACT)


@pytest.mark.parametrize("slope", [0.0, 0.3, -0.4, 1.5, 6.0])
@pytest.mark.parametrize("area", [0.002, 0.0152, 0.0304])
def test_surface_offset_bounds_the_area(slope: float, area: float) -> None:
    b = SEED.inner_width
    c = surface_offset(b, slope, area)
    x = np.linspace(-b / 2, b / 2, 200001)
    integral = float(np.trapezoid(np.clip(c + slope * x, 0.0, None), x))
    assert integral == pytest.approx(area, abs=AREA_QUADRATURE_TOL)
    (x0, z0), (x1, z1) = surface_chord(b, slope, area)
    assert min(z0, z1) >= -EXACT and x0 < x1


def test_static_h_q_matches_eq16_for_a_thin_wall() -> None:
    """Eq. 16: tan(theta) = (2/B)(h_q + h_e), h_q along the vessel axis at the wall, wall thickness 0."""
    thin = VesselGeometry(wall_thickness=0.0)
    a_fill = 0.1591
    area = thin.inner_width * a_fill
    h_e = thin.inner_height - a_fill
    for h_axis in (0.0, 0.003, 0.005, 0.01):
        theta = eq16_tilt(thin.inner_width, h_e, h_axis)
        # world-vertical height over the crest = axial height * cos(theta) for a level surface
        assert static_h_q(thin, theta, area) == pytest.approx(h_axis * math.cos(theta), abs=EXACT)
        h_world = h_axis * math.cos(theta)
        assert static_tilt_for_h_q(thin, h_world, area) == pytest.approx(theta, abs=1e-12)


def test_static_h_q_grows_with_tilt_and_handles_the_floor() -> None:
    area = SEED.inner_width * 0.054  # the paper's lowest fill: the surface reaches the floor before the crest
    thetas = np.linspace(0.0, 1.4, 300)
    h = np.array([static_h_q(SEED, th, area) for th in thetas])
    assert np.all(np.diff(h) > 0)
    contact = static_tilt_for_h_q(SEED, 0.0, area)
    assert static_h_q(SEED, contact, area) == pytest.approx(0.0, abs=1e-12)
    assert math.tan(contact) * SEED.inner_width / 2 > 0.054  # past the wall-to-wall range


def test_vector_step_lowers_the_point_by_dh_exactly() -> None:
    for a in [(0.1005, 0.191), (0.16, 0.145), (-0.05, 0.1), (0.05, -0.03)]:
        for dh in (0.005, -0.004, 0.0001):
            step = vector_step(a, dh)
            x, z = rotate(step, a)
            assert z == pytest.approx(a[1] - dh, abs=EXACT)
            assert math.hypot(x, z) == pytest.approx(math.hypot(*a), abs=EXACT)
    # out of reach (the circle's top is below a_z - dh): the tip goes to the top of the circle
    a = (-0.02, 0.1)
    assert rotate(vector_step(a, -0.004), a) == pytest.approx((0.0, math.hypot(*a)), abs=EXACT)


def test_the_seeds_literal_angle_lowers_the_point_by_only_cos2_elevation_dh() -> None:
    """Turning by the angle between a and c = a - b (Fig. 9 read literally) lowers the tip by cos^2(beta) dh to
    first order (beta = elevation of a): for the paper's crest seen from the floor centre only 22 % of dh. Hence
    vector_step solves for the exact drop, which is what the paper's text asks for."""
    dh = 1e-5
    for a in [(0.1005, 0.191), (0.0955, 0.032), (0.2, 0.0)]:
        literal = math.atan2(a[1], a[0]) - math.atan2(a[1] - dh, a[0])
        drop = a[1] - rotate(literal, a)[1]
        beta = math.atan2(a[1], a[0])
        assert drop == pytest.approx(math.cos(beta) ** 2 * dh, rel=1e-3)


def test_vector_step_about_the_surface_midpoint_raises_static_h_q_by_dh() -> None:
    """Wall-to-wall surface: lowering the crest by dh about the surface midpoint is exactly +dh of h_q."""
    area = SEED.inner_width * 0.1591
    for theta in (0.30, 0.36, 0.45):
        for dh in (0.001, 0.005, -0.002):
            step = vector_step(crest_lever(SEED, theta, area), dh)
            gained = static_h_q(SEED, theta + step, area) - static_h_q(SEED, theta, area)
            assert gained == pytest.approx(dh, abs=EXACT)


def test_height_above_is_the_world_vertical_distance() -> None:
    theta, theta1, c = 0.4, 0.45, 0.15
    px, pz = SEED.crest
    h = height_above((px, pz), c, theta1, theta)
    # walk up along world z from the crest by h: that point lies on the surface line (vessel frame)
    up_x, up_z = rotate(-theta, (0.0, h))
    assert pz + up_z == pytest.approx(c + math.tan(theta1) * (px + up_x), abs=EXACT)


def test_vessel_validation() -> None:
    from controllers.errors import ControllerInputError

    with pytest.raises(ControllerInputError, match=r"^vessel\.wall_thickness: must be in \[0, 0\.2\] m, got 0\.3$"):
        VesselGeometry(wall_thickness=0.3)
