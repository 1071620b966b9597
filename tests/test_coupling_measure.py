"""The controller's measurement contract (controllers.measurement.LiquidMeasurement) on synthetic particles."""

import math

import numpy as np
import pytest

from controllers.geometry import VesselGeometry, static_h_q
from cosim.coupling.measure import MeasurementGeometry, free_surface_fit, measure
from cosim.frames import Pose, rotation_y
from cosim.vessel import seed_pouring_vessel

SPEC = seed_pouring_vessel()
DX = SPEC.inner_width / 40
H = 1.5 * DX
WALL = 3 * DX
GEO = MeasurementGeometry(SPEC, WALL, 0.16, H, DX, initial_volume=0.003, dim=2)
# A lattice surface is exact to half a spacing: angles within atan(dx / B) of the truth, heights within dx.
ANGLE_TOLERANCE = math.atan(DX / SPEC.inner_width)


def _level_liquid(tilt: float, area: float) -> tuple[Pose, np.ndarray]:
    """A resting liquid of cross-section ``area`` (m^2) in the seed vessel tilted by ``tilt`` about the lip."""
    lip = SPEC.lip_local
    rot = rotation_y(tilt)
    pose = Pose(lip - rot @ lip, rot)
    geom = VesselGeometry(SPEC.inner_width, SPEC.inner_height, WALL, SPEC.inner_depth)
    level = static_h_q(geom, tilt, area)  # crest height above the surface, world z
    crest = pose.transform(np.array([[0.5 * SPEC.inner_width, 0.0, SPEC.inner_height]]))[0]
    surface_z = crest[2] + level
    b = 0.5 * SPEC.inner_width
    xs = np.arange(-b + 0.5 * DX, b, DX)
    zs = np.arange(0.5 * DX, SPEC.inner_height, DX)
    local = np.array([(x, 0.0, z) for x in xs for z in zs])
    world = pose.transform(local)
    return pose, world[world[:, 2] <= surface_z]


@pytest.mark.parametrize("tilt_deg", [0.0, 10.0, 25.0])
def test_level_liquid_gives_theta1_equal_to_tilt(tilt_deg):
    tilt = math.radians(tilt_deg)
    pose, x = _level_liquid(tilt, 0.191 * 0.12)
    catcher = Pose((0.4, 0.0, -0.3))
    m = measure(1.0, GEO, pose, catcher, x, np.zeros_like(x), np.ones(len(x), bool), 0.002)
    assert m.tilt == pytest.approx(tilt, abs=1e-9)
    assert abs(m.theta1 - tilt) <= ANGLE_TOLERANCE
    assert m.h_q < 0.0  # the surface is below the crest
    assert m.v_q == 0.0 and m.poured_volume == pytest.approx(0.001)
    assert m.catcher_rim_z == pytest.approx(-0.3 + 0.16)


def test_liquid_over_the_crest_and_leaving_at_the_lip():
    pose = Pose()
    crest = np.array([0.5 * SPEC.inner_width, 0.0, SPEC.inner_height])
    over = crest + np.array([0.0, 0.0, 0.004])  # a particle centre 4 mm over the crest
    lip = GEO.lip_local
    leaving = np.array([lip + [0.002, 0.0, 0.001], lip + [-0.003, 0.0, 0.0]])
    x = np.vstack([over, leaving])
    v = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, -0.1], [0.5, 0.0, -0.3]])
    m = measure(0.5, GEO, pose, Pose((0.4, 0.0, -0.3)), x, v, np.ones(3, bool), 0.0029)
    assert m.h_q == pytest.approx(0.004 + 0.5 * DX, abs=1e-9)
    assert m.v_q == pytest.approx(0.4)
    assert m.v_q_z == pytest.approx(-0.2)
    assert (m.lip_x, m.lip_z) == pytest.approx((lip[0], lip[2]))


def test_free_surface_fit_recovers_a_slope():
    xs = np.linspace(-0.09, 0.09, 60)
    local = np.array([(x, 0.0, 0.1 + 0.2 * x - k * 0.004) for x in xs for k in range(5)])
    c, slope, columns = free_surface_fit(local, SPEC.inner_width, H)
    assert columns >= 3
    assert slope == pytest.approx(0.2, abs=0.02) and c == pytest.approx(0.1, abs=0.003)
