"""First-mode slosh model of an upright vessel from linear potential flow, and the controller's plant Gp.

Frames and signs (the whole package uses these):
  * Pour plane = world x-z, pour direction +x, z up. Vessel frame: origin at the centre of the inner floor,
    +x toward the pour lip, +z up the vessel's axis.
  * Vessel tilt theta (rad): rotation about world +y, R_y(theta) = [[c, 0, s], [0, 1, 0], [-s, 0, c]];
    theta > 0 lowers the +x lip (pours).
  * Free-surface angle theta1 (rad): the angle of the liquid's free surface in the VESSEL frame, positive when
    the surface stands higher at the lip wall (+x) than at the back wall: theta1 = atan(dz_v/dx_v) of the line
    fitted to the free surface in vessel coordinates. A liquid at rest in a vessel tilted by theta has
    theta1 = theta (the surface stays level in the world). See :class:`controllers.measurement.LiquidMeasurement`.
  * Slosh angle sigma = theta1 - theta (rad): the free surface's angle to the world horizontal, positive when it
    stands higher toward +x. sigma = 0 whenever the liquid is at rest, whatever the tilt.

First mode from linear potential flow (Faltinsen & Timokha, "Sloshing", 2009, Ch. 4-5; Ibrahim, "Liquid Sloshing
Dynamics", 2005, Ch. 1 and 7). Liquid of depth A at rest in an upright vessel, z from the inner floor. The first
antisymmetric mode's velocity potential and its wave number k are

    box of inner width B (slosh along B):      phi1 = sin(k x) cosh(k z),                 k = pi / B
    cylinder of inner radius R:                phi1 = J1(k r) cos(psi) cosh(k z),          k = xi / R,
                                               xi = 1.8412, the first root of J1'

and its frequency follows from the free-surface condition: omega1^2 = g k tanh(k A). The equivalent pendulum
(length l1, Abramson, NASA SP-106, 1966) has the same frequency: l1 = g / omega1^2 = coth(k A) / k.

The hinge. A vessel rotating by theta about a pivot at height p on its axis forces the mode through the wall
and floor motion; in the modal equation the forcing is lambda_x x'' + lambda_r theta'' (+ the gravity term
g lambda_x theta), x = -p theta the axis point's sideways motion at the floor. By reciprocity lambda_x and
lambda_r are the horizontal force and the moment about the floor centre of the mode's pressure (proportional to
phi1) on the walls and floor. The pivot about which a rotation leaves the mode unforced, the hinge, is

    H = lambda_r / lambda_x = A - (cosh(k A) - 2) / (k sinh(k A)),

for the box (walls: 2 sinh(kA)/k and 2 [A sinh(kA)/k - (cosh(kA) - 1)/k^2]; floor: int x sin(kx) dx = 2/k^2)
and for the cylinder alike (its floor term pi R^2 J2(xi)/k over the wall force pi R J1(xi) sinh(kA)/k gives the
same 2, since J2(xi) = J1(xi)/xi where J1'(xi) = 0). H is the height of Housner's convective force including the
floor pressure (Housner, 1963); deep liquid: H -> A - 1/k, i.e. B/pi (box) or R/xi (cylinder) below the surface.

The model used by the controller: a pendulum of length l1 hanging from the vessel-frame point (0, H),

    l1 sigma'' + 2 zeta omega1 l1 sigma' + g sigma = -x_h''                                      (M)

x_h the world x of the hinge, zeta a damping ratio (0 for potential flow; the SPH liquid's is identified by
``cosim validate slosh-plant``). For a rotation about the floor centre (x_h = H theta for small angles) and
b2 = l1 - H this is Gp(s) = theta1/theta = (b2 s^2 + 2 zeta omega1 l1 s + g) / (l1 s^2 + 2 zeta omega1 l1 s + g),
the form of Camporredondo et al. (2019), Eq. 14 (DC gain +1). Rotating about a pivot below the hinge (the floor
centre, SIM) excites the slosh, about the hinge not at all (the approach), about a pivot above it (the lip, CFS)
with the opposite sign, which keeps the CFS integral law stable (:mod:`controllers.cfs`). b2 < 0 for every fill:
Gp has a real right-half-plane zero at sqrt(g / -b2).

Where this departs from the paper: its Eqs. 10-11 as printed put the hinge at l1 - b2 = 3 l1 - (2B/pi)
tanh(pi A/B), 64 mm above the floor for its own vessel (B = 0.191 m, A = 0.1591 m), where potential flow puts it
at H = 115.5 mm (b2 = -54 mm instead of -2.7 mm; the RHP zero at 13.5 rad/s instead of 61). The tilts of the
project's SPH liquid about several pivots agree with H (``cosim validate slosh-plant``). The printed model is kept
as :func:`printed_paper_model`, only to reproduce the paper's figures (:mod:`cosim.tools.controller_figures`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from functools import cached_property
from typing import TYPE_CHECKING

from controllers.checks import check_choice, check_range
from declared_settings.setting import REQUIRED, check_settings, documented, setting

if TYPE_CHECKING:  # python-control (and scipy) take seconds to load, NumPy a fraction of one: imported by the
    import control as ct  # functions that use them, so that reading a configuration stays fast
    import numpy as np

GRAVITY = 9.81  # m/s^2
J1_PRIME_FIRST_ROOT = 1.8411837813406593  # first positive root of J1'(x), the cylinder's first antisymmetric mode


class VesselShape(Enum):
    """Cross-section of an upright vessel."""

    BOX = "box"  # slosh along the inner width B
    CYLINDER = "cylinder"  # inner diameter D = 2 R


def first_mode_wavenumber(shape: VesselShape, width: float) -> float:
    """k (1/m) of the first antisymmetric mode: pi / B for a box of inner width B, xi / R for a cylinder of inner
    diameter ``width`` = 2 R (m)."""
    shape = check_choice("slosh.shape", shape, VesselShape)
    check_range("slosh.width", width, 0.0, 2.0, "m", lo_open=True)
    return math.pi / width if shape is VesselShape.BOX else 2.0 * J1_PRIME_FIRST_ROOT / width


def first_mode_frequency(width: float, fill_depth: float, gravity: float = GRAVITY,
                         shape: VesselShape = VesselShape.BOX) -> float:
    """First sloshing frequency (Hz): omega1^2 = g k tanh(k A); f = omega1 / (2 pi). ``width`` B (box) or the
    inner diameter (cylinder) and ``fill_depth`` A in m."""
    k = first_mode_wavenumber(shape, width)
    return math.sqrt(gravity * k * math.tanh(k * fill_depth)) / (2.0 * math.pi)


SLOSH = "first slosh mode"


@documented
@dataclass(frozen=True)
class SloshModel:
    """The first-mode pendulum (M). ``source`` says where the numbers come from.

    Build it with :func:`potential_flow_model` (the default everywhere), from an SPH identification
    (``cosim validate slosh-plant``), or with :func:`printed_paper_model` to reproduce the paper's figures.
    Lengths in m, frequencies in rad/s unless the name says Hz.
    """

    l1: float = setting(REQUIRED, SLOSH, "Length of the equivalent pendulum, g / omega1^2.", "m", 0.0, 10.0,
                        lo_open=True)
    hinge_height: float = setting(REQUIRED, SLOSH, "Height of the pendulum's hinge H above the inner floor, on the "
                                  "vessel's axis.", "m", -2.0, 2.0)
    damping_ratio: float = setting(0.0, SLOSH, "The mode's damping ratio zeta (0 for potential flow).", "", 0.0, 1.0,
                                   hi_open=True)
    gravity: float = setting(GRAVITY, SLOSH, "Gravity's magnitude.", "m/s^2", 0.0, 100.0, lo_open=True)
    source: str = "potential flow"

    def __post_init__(self) -> None:
        check_settings(self, "slosh")

    @property
    def b2(self) -> float:
        """b2 = l1 - H (m), the s^2 coefficient of Gp's numerator; negative when the hinge is above l1."""
        return self.l1 - self.hinge_height

    @cached_property
    def omega1(self) -> float:
        """First-mode angular frequency sqrt(g / l1) (rad/s)."""
        return math.sqrt(self.gravity / self.l1)

    @property
    def period(self) -> float:
        """First-mode period 2 pi / omega1 (s)."""
        return 2.0 * math.pi / self.omega1

    @property
    def rhp_zero(self) -> float:
        """The real right-half-plane zero of the undamped Gp, sqrt(g / -b2) (rad/s); inf when b2 >= 0."""
        return math.sqrt(self.gravity / -self.b2) if self.b2 < 0.0 else math.inf

    @property
    def damping_coefficient(self) -> float:
        """c = 2 zeta omega1 l1 (m/s), the first-order coefficient of (M)."""
        return 2.0 * self.damping_ratio * self.omega1 * self.l1

    def plant(self, pivot_height: float = 0.0) -> ct.TransferFunction:
        """theta1(s)/theta(s) for a rotation about a pivot ``pivot_height`` (m) above the floor centre.

        The hinge then moves by x_h = (H - p) theta (small angles), so (M) gives
        ((b2 + p) s^2 + c s + g) / (l1 s^2 + c s + g), c = 2 zeta omega1 l1. ``pivot_height = 0`` is Gp. About a
        tilt theta0 and any vessel-frame pivot, the linearised plant is this one with
        pivot_height = hinge_height + :meth:`pivot_above_hinge` (pivot, theta0).
        """
        import control as ct

        c = self.damping_coefficient
        return ct.tf([self.b2 + pivot_height, c, self.gravity], [self.l1, c, self.gravity])

    def pivot_above_hinge(self, pivot: tuple[float, float], tilt: float) -> float:
        """World height (m) of the vessel-frame point ``pivot`` above the hinge (0, H), at tilt ``tilt`` (rad).

        Rotating about a pivot above the hinge swings the hinge backward as the vessel tilts forward, like a
        hanging pendulum: the plant's s^2 coefficient b2 + p then exceeds l1, which is what makes the CFS
        integral law stable (:mod:`controllers.cfs`).
        """
        px, pz = pivot
        return -px * math.sin(tilt) + (pz - self.hinge_height) * math.cos(tilt)

    def forced_ratio(self, alpha: np.ndarray | float) -> np.ndarray:
        """Signed theta1/theta of the undamped forced response to theta = phi sin(alpha t) about the floor centre
        (paper Eq. 13, written there for theta_n = -theta1), alpha in rad/s: (g - b2 alpha^2) / (g - l1 alpha^2).
        """
        import numpy as np

        a2 = np.asarray(alpha, dtype=float) ** 2
        return (self.gravity - self.b2 * a2) / (self.gravity - self.l1 * a2)

    def state_space(self) -> ct.StateSpace:
        """The pendulum in the world: input x_h, the world x (m) of the hinge point (0, H) of the vessel frame;
        output sigma (rad), the slosh angle; theta1 = theta + sigma.

        (M) driven by the hinge's exact motion, which keeps large tilts right. With w2 = g / l1, d = 2 zeta omega1
        and q = sigma + x_h / l1, (M) reads q'' + d q' + w2 q = (w2 x_h + d x_h') / l1: the state is z, z' with
        z'' + d z' + w2 z = x_h, and sigma = (w2 z + d z') / l1 - x_h / l1.
        """
        import control as ct

        w2 = self.gravity / self.l1
        d = 2.0 * self.damping_ratio * self.omega1
        return ct.ss([[0.0, 1.0], [-w2, -d]], [[0.0], [1.0]], [[w2 / self.l1, d / self.l1]], [[-1.0 / self.l1]])


def potential_flow_model(width: float, fill_depth: float, gravity: float = GRAVITY,
                         shape: VesselShape = VesselShape.BOX) -> SloshModel:
    """The first-mode pendulum of a liquid of depth ``fill_depth`` (A, m) in an upright box of inner width
    ``width`` (B, m) or a cylinder of inner diameter ``width``: l1 = coth(kA)/k, H = A - (cosh(kA) - 2)/(k sinh(kA))
    (module docstring)."""
    check_range("slosh.fill_depth", fill_depth, 0.0, 2.0, "m", lo_open=True)
    k = first_mode_wavenumber(shape, width)
    ka = k * fill_depth
    hinge = fill_depth - (math.cosh(ka) - 2.0) / (k * math.sinh(ka)) if ka < 300.0 else fill_depth - 1.0 / k
    return SloshModel(1.0 / (k * math.tanh(ka)), hinge, 0.0, gravity, f"potential flow ({VesselShape(shape).value})")


def printed_paper_model(width: float, fill_depth: float, gravity: float = GRAVITY) -> SloshModel:
    """The pendulum exactly as Camporredondo et al. (2019) print it (Eqs. 10-11, with the L1 they quote):
    l1 = (B/pi) coth(pi A/B), L1 = l1 + A/2 - (2B/pi) tanh(pi A/B), b2 = A/2 - L1 - l1, hinge l1 - b2.

    Only for reproducing the paper's figures: its hinge disagrees with potential flow and with the SPH liquid
    (module docstring)."""
    check_range("slosh.fill_depth", fill_depth, 0.0, 2.0, "m", lo_open=True)
    k = first_mode_wavenumber(VesselShape.BOX, width)
    l1 = 1.0 / (k * math.tanh(k * fill_depth))
    printed_l1_offset = l1 + 0.5 * fill_depth - 2.0 / k * math.tanh(k * fill_depth)
    b2 = 0.5 * fill_depth - printed_l1_offset - l1
    return SloshModel(l1, l1 - b2, 0.0, gravity, "paper, Eqs. 10-11 as printed")
