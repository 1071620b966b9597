"""Planar geometry of the pour: vessel poses, pivots, the static liquid in a tilted box, the CFS vector step.

Frames (see also :mod:`controllers.slosh`): the pour plane is world x-z (x toward the pour, z up); points are
(x, z) pairs in m. The vessel frame has its origin at the centre of the inner floor, +x toward the pour lip,
+z up the vessel's axis; at the home pose the vessel stands upright with its +x along world +x. A tilt theta
(rad, rotation about world +y) maps vessel-frame (x, z) to world offsets R(theta) (x, z) =
(x cos + z sin, -x sin + z cos), so theta > 0 lowers the +x lip.

A :class:`PlanarPose` (dx, dz, theta) is the vessel pose relative to home: vessel-frame origin at
home_pos + (dx, 0, dz), orientation R_y(theta) R_home.

Static liquid: at rest the free surface is level in the world, i.e. a line of slope tan(theta) in the vessel
frame; more generally (a sloshing liquid, :mod:`controllers.model_plant`) a line of slope tan(theta1). Its offset
follows from the liquid's area in the pour plane (volume / inner depth), which the line bounds with the floor
and walls. Liquid above the walls' tops is not represented (it is the outflow head over the crest).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from controllers.slosh import VesselShape
from declared_settings.setting import check_settings, documented, setting

MAX_STATIC_TILT = 0.5 * math.pi - 1e-6  # rad; the static liquid formulas need a tilt below 90 deg
BISECTION_STEPS = 60  # halvings of [0, 90 deg): 1.4e-18 rad resolution, far below float64 on the angle


def rotate(theta: float, p: tuple[float, float]) -> tuple[float, float]:
    """World offset (x, z) of the vessel-frame vector ``p`` at tilt ``theta`` (rad)."""
    c, s = math.cos(theta), math.sin(theta)
    return (p[0] * c + p[1] * s, -p[0] * s + p[1] * c)


@dataclass(frozen=True)
class PlanarPose:
    """Vessel pose relative to home: origin offset (dx, dz) in m (world x, z), tilt theta in rad about +y."""

    dx: float = 0.0
    dz: float = 0.0
    theta: float = 0.0

    def point(self, p_local: tuple[float, float]) -> tuple[float, float]:
        """World offset from the home origin of the vessel-frame point ``p_local``."""
        rx, rz = rotate(self.theta, p_local)
        return (self.dx + rx, self.dz + rz)

    def rotated_about(self, pivot_local: tuple[float, float], theta: float) -> PlanarPose:
        """The pose with tilt ``theta`` whose vessel-frame point ``pivot_local`` stays where it is now.

        Continuous in theta for any pivot, so the pivot may change between steps without a jump.
        """
        wx, wz = self.point(pivot_local)
        rx, rz = rotate(theta, pivot_local)
        return PlanarPose(wx - rx, wz - rz, theta)


VESSEL = "vessel"


@documented
@dataclass(frozen=True)
class VesselGeometry:
    """The pouring vessel, an open box (vessel 1 of Camporredondo et al. 2019)."""

    inner_width: float = setting(0.191, VESSEL, "B, along the pour direction (vessel x).", "m", 0.0, 2.0, lo_open=True)
    inner_height: float = setting(0.191, VESSEL, "L, floor to rim (vessel z).", "m", 0.0, 2.0, lo_open=True)
    wall_thickness: float = setting(0.005, VESSEL, "t, the walls' thickness.", "m", 0.0, 0.2)
    inner_depth: float = setting(0.100, VESSEL, "Perpendicular to the pour plane (vessel y); volume = area in the pour "
                                 "plane * inner_depth.", "m", 0.0, 2.0, lo_open=True)
    shape: VesselShape = setting(
        VesselShape.BOX, VESSEL, "The liquid's horizontal section, which sets its slosh mode "
        "(controllers.slosh.potential_flow_model): 'box', or 'cylinder' of inner diameter inner_width (a 3-D liquid in "
        "a cup; the static liquid is then that of the box of equal floor area, inner_depth = pi inner_width / 4, the "
        "same volume at every fill).")

    def __post_init__(self) -> None:
        check_settings(self, "vessel")

    @property
    def lip(self) -> tuple[float, float]:
        """Pour lip, vessel frame: outer top edge of the +x wall, where the liquid leaves (jet launch point)."""
        return (0.5 * self.inner_width + self.wall_thickness, self.inner_height)

    @property
    def crest(self) -> tuple[float, float]:
        """Crest point, vessel frame: inner top edge of the +x wall, the highest point of the wall top for
        theta >= 0. h_q is the liquid height over this point."""
        return (0.5 * self.inner_width, self.inner_height)

    def area(self, volume: float) -> float:
        """Liquid area in the pour plane (m^2) of ``volume`` (m^3)."""
        return volume / self.inner_depth


def surface_offset(width: float, slope: float, area: float) -> float:
    """Height c (m) at x = 0 of the vessel-frame line z = c + slope x that bounds ``area`` (m^2) in a box.

    The area under the line over x in [-width/2, width/2], clipped at the floor z = 0: width * c while the line
    spans wall to wall (c >= |slope| width/2), else the triangle (c + |slope| width/2)^2 / (2 |slope|).
    """
    m = abs(slope)
    if area >= 0.5 * m * width * width:
        return area / width
    return math.sqrt(2.0 * m * area) - 0.5 * m * width


def surface_chord(width: float, slope: float, area: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Vessel-frame end points (m) of the free surface z = c + slope x bounding ``area`` (m^2): wall to wall,
    or from the floor to the wall the liquid leans on."""
    c = surface_offset(width, slope, area)
    x_lo, x_hi = -0.5 * width, 0.5 * width
    if slope > 0.0 and c + slope * x_lo < 0.0:
        x_lo = -c / slope
    elif slope < 0.0 and c + slope * x_hi < 0.0:
        x_hi = -c / slope
    return (x_lo, c + slope * x_lo), (x_hi, c + slope * x_hi)


def surface_midpoint(width: float, slope: float, area: float) -> tuple[float, float]:
    """Vessel-frame midpoint of the free-surface chord (m). For a wall-to-wall surface it is (0, area/width),
    the point the surface turns about when the vessel tilts with the area unchanged."""
    (x0, z0), (x1, z1) = surface_chord(width, slope, area)
    return (0.5 * (x0 + x1), 0.5 * (z0 + z1))


def height_above(point: tuple[float, float], c: float, theta1: float, theta: float) -> float:
    """World-vertical height (m) of the line z = c + tan(theta1) x (vessel frame) above the vessel-frame
    ``point``, with the vessel tilted by ``theta``; negative when the line is below the point."""
    px, pz = point
    t1 = math.tan(theta1)
    return (c + px * t1 - pz) / (math.cos(theta) + math.sin(theta) * t1)


def static_h_q(geom: VesselGeometry, theta: float, area: float) -> float:
    """h_q (m) of a liquid at rest (level surface) of ``area`` (m^2) in the vessel tilted by ``theta`` (rad)."""
    c = surface_offset(geom.inner_width, math.tan(theta), area)
    return height_above(geom.crest, c, theta, theta)


def static_tilt_for_h_q(geom: VesselGeometry, h_q: float, area: float) -> float:
    """Tilt (rad) at which a liquid at rest of ``area`` (m^2) stands ``h_q`` (m) over the crest.

    static_h_q grows monotonically with the tilt on [0, 90 deg); solved by bisection. Returns 0 if the liquid
    already stands that high upright. Generalises the paper's Eq. 16, theta = atan(2 (h_q + h_e) / B), which is
    the wall-to-wall case with t = 0 and h_q measured along the vessel axis (see :func:`eq16_tilt`).
    """
    lo, hi = 0.0, MAX_STATIC_TILT
    if static_h_q(geom, lo, area) >= h_q:
        return 0.0
    for _ in range(BISECTION_STEPS):
        mid = 0.5 * (lo + hi)
        if static_h_q(geom, mid, area) < h_q:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def eq16_tilt(width: float, empty_height: float, h_q: float) -> float:
    """Camporredondo et al. (2019), Eq. 16: theta_V = atan((2/B) (h_q + h_e)) (rad); B, h_e = L - A, h_q in m."""
    return math.atan(2.0 / width * (h_q + empty_height))


def vector_step(a: tuple[float, float], dh: float) -> float:
    """Tilt increment (rad) lowering the tip of ``a`` by ``dh``: the CFS vector step (Camporredondo et al., Fig. 9).

    ``a`` (m, world x-z) goes from the centre of rotation to the point at the lip; b = (0, dh) is the vertical
    step at that point and c = a - b. Turning by the angle between a and c, as Fig. 9 reads literally, lowers
    the tip by only cos^2(beta) dh to first order (beta = elevation of a; the tip stays at length |a|, not |c|).
    This returns the rotation (in the tilt sense) that brings the tip of a exactly to the height of c, i.e. down
    by dh, as the paper's text asks. dh < 0 raises the point. A dh beyond the reach of the circle is clipped.
    """
    import numpy as np

    ax, az = a
    r = math.hypot(ax, az)
    beta = math.atan2(az, ax)
    s = min(max((az - dh) / r, -1.0), 1.0)
    beta_new = math.asin(s) if ax >= 0.0 else math.pi - math.asin(s)
    return float(np.angle(np.exp(1j * (beta - beta_new))))
