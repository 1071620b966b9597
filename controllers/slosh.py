"""First-mode slosh pendulum model of a rectangular vessel (seed Eqs. 9-14, 17) and its plant Gp.

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

Model (equivalent pendulum, Abramson NASA SP-106; Ibrahim 2005; seed Eqs. 8-9 with n = 1, in the convention
above). With x the world x of the vessel frame origin,

    l1 theta1'' + g theta1 = b2 theta'' + g theta - x''                                          (M)

so that Gp(s) = theta1(s)/theta(s) = (b2 s^2 + g) / (l1 s^2 + g) for a rotation about the inner floor centre
(x = const). This is the seed's printed Eq. 14 (DC gain +1: the "steady-state error of one half" of the seed's
unity-feedback loop). The seed's Eq. 9 measures the pendulum angle theta_n in the opposite sense
(theta_n = -theta1), which is where the reference README's minus sign comes from; both describe the same physics.
The -x'' term has the sign of the quasi-static limit: accelerating the vessel toward +x piles the liquid at the
back wall (sigma = -x''/g). (M) is a pendulum of length l1 hanging from the vessel-frame point (0, l1 - b2),
the "hinge": l1 sigma'' + g sigma = -(world x of the hinge)''. Rotating about a pivot below the hinge
(the floor centre, SIM) excites the slosh, about the hinge not at all (the approach), about a pivot above it
(the lip, CFS) with the opposite sign, which is what keeps the CFS integral law stable (:mod:`controllers.cfs`).

Pendulum parameters (seed Eqs. 10-11). The seed writes them with the vessel height L; its vessel has L = B, and
the pendulum reproduces the first sloshing frequency (Eq. 17, omega1^2 = g / l1) only with the width B in the
slosh direction, so B is used here:
    l1 = (B/pi) coth(pi A / B)
    L1 = l1 + A/2 - (2B/pi) tanh(pi A / B)
    b2 = A/2 - L1 - l1 = -(4B/pi) / sinh(2 pi A / B)   (< 0 for every fill)
Eq. 11 as printed carries an extra overall minus sign, which gives L1 = -0.0207 m for the seed's vessel; the seed
then quotes L1 = +0.0207 m and works with b2 = -0.0027 m (the right-half-plane zero its PID discussion is about),
as does the project's reference README. The quoted sign is implemented.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from controllers.checks import check_range

if TYPE_CHECKING:  # python-control (and scipy) take seconds to load: imported by the functions that build
    import control as ct  # transfer functions, so that reading a configuration stays fast

GRAVITY = 9.81  # m/s^2, as in the seed (its SPH gravity vector is [0, 9.81, 0] m/s^2)


def first_mode_frequency(width: float, fill_depth: float, gravity: float = GRAVITY) -> float:
    """First sloshing frequency (Hz) of a rectangular tank (seed Eq. 17, reference README).

    omega^2 = (g pi / B) tanh(pi A / B); f = omega / (2 pi). ``width`` B and ``fill_depth`` A in m.
    """
    return math.sqrt(gravity * math.pi / width * math.tanh(math.pi * fill_depth / width)) / (2.0 * math.pi)


@dataclass(frozen=True)
class SloshModel:
    """The first-mode pendulum of a liquid of depth ``fill_depth`` (A, m) in a vessel of inner width ``width`` (B, m).

    All lengths in m, frequencies in rad/s unless the name says Hz. See the module docstring for frames and signs.
    Derived parameters are computed once (the instance is immutable).
    """

    width: float
    fill_depth: float
    gravity: float = GRAVITY

    def __post_init__(self) -> None:
        check_range("slosh.width", self.width, 0.0, 2.0, "m", lo_open=True)
        check_range("slosh.fill_depth", self.fill_depth, 0.0, 2.0, "m", lo_open=True)
        check_range("slosh.gravity", self.gravity, 0.0, 100.0, "m/s^2", lo_open=True)

    @cached_property
    def _k(self) -> float:
        """pi A / B (dimensionless)."""
        return math.pi * self.fill_depth / self.width

    @cached_property
    def l1(self) -> float:
        """Pendulum length (m), Eq. 10."""
        return self.width / math.pi / math.tanh(self._k)

    @cached_property
    def L1(self) -> float:  # noqa: N802 (the seed's symbol)
        """Pendulum hinge offset (m), Eq. 11 with the seed's quoted sign (see module docstring)."""
        return self.l1 + 0.5 * self.fill_depth - 2.0 * self.width / math.pi * math.tanh(self._k)

    @cached_property
    def b2(self) -> float:
        """b2 = A/2 - L1 - l1 (m), Eq. 14; negative for every fill, which puts a zero in the right half-plane."""
        return 0.5 * self.fill_depth - self.L1 - self.l1

    @cached_property
    def omega1(self) -> float:
        """First-mode angular frequency sqrt(g / l1) (rad/s); equals 2 pi times Eq. 17."""
        return math.sqrt(self.gravity / self.l1)

    @property
    def period(self) -> float:
        """First-mode period 2 pi / omega1 (s)."""
        return 2.0 * math.pi / self.omega1

    @property
    def rhp_zero(self) -> float:
        """The right-half-plane zero sqrt(g / -b2) of Gp (rad/s)."""
        return math.sqrt(self.gravity / -self.b2)

    @cached_property
    def hinge_height(self) -> float:
        """Height above the inner floor (m) of the pivot that leaves the slosh unexcited: l1 - b2.

        Rotating about the point (0, l1 - b2) of the vessel frame cancels the theta'' forcing of (M) to first
        order (the pendulum's hinge stays put). The seed's "rotate about the liquid's centre of mass" for pours
        without SIM is the same idea with a heuristic point.
        """
        return self.l1 - self.b2

    def plant(self, pivot_height: float = 0.0) -> ct.TransferFunction:
        """theta1(s)/theta(s) for a rotation about a pivot ``pivot_height`` (m) above the floor centre.

        The origin then moves by x = -pivot_height * theta (small angles), so (M) gives
        ((b2 + p) s^2 + g) / (l1 s^2 + g). ``pivot_height = 0`` is the seed's Gp (Eq. 14). About a tilt theta0
        and any vessel-frame pivot, the linearised plant is this one with
        pivot_height = hinge_height + :meth:`pivot_above_hinge` (pivot, theta0).
        """
        import control as ct

        return ct.tf([self.b2 + pivot_height, 0.0, self.gravity], [self.l1, 0.0, self.gravity])

    def pivot_above_hinge(self, pivot: tuple[float, float], tilt: float) -> float:
        """World height (m) of the vessel-frame point ``pivot`` above the hinge (0, l1 - b2), at tilt ``tilt`` (rad).

        Rotating about a pivot above the hinge swings the hinge backward as the vessel tilts forward, like a
        hanging pendulum: the plant's s^2 coefficient b2 + p then exceeds l1, which is what makes the CFS
        integral law stable (:mod:`controllers.cfs`).
        """
        px, pz = pivot
        return -px * math.sin(tilt) + (pz - self.hinge_height) * math.cos(tilt)

    def forced_ratio(self, alpha: np.ndarray | float) -> np.ndarray:
        """Signed theta1/theta of the forced response to theta = phi sin(alpha t) (seed Eq. 13), alpha in rad/s.

        (g - b2 alpha^2) / (g - l1 alpha^2): +1 at alpha = 0, infinite at resonance alpha = omega1, -> b2/l1 above.
        Eq. 13 prints the same with the opposite sign because it is written for theta_n = -theta1.
        """
        a2 = np.asarray(alpha, dtype=float) ** 2
        return (self.gravity - self.b2 * a2) / (self.gravity - self.l1 * a2)

    def state_space(self) -> ct.StateSpace:
        """The pendulum in the world: input x_h, the world x (m) of the hinge point (0, l1 - b2) of the vessel
        frame; output sigma (rad), the slosh angle; theta1 = theta + sigma.

        l1 sigma'' + g sigma = -x_h'' (a pendulum whose hinge moves sideways). With x_h = x + (l1 - b2) sin(theta)
        and small angles this is (M); for large tilts it keeps the hinge's exact motion. State
        q = sigma + x_h / l1 and its rate: q'' = -w^2 q + (w^2 / l1) x_h, sigma = q - x_h / l1, w^2 = g / l1.
        """
        import control as ct

        w2 = self.gravity / self.l1
        return ct.ss([[0.0, 1.0], [-w2, 0.0]], [[0.0], [w2 / self.l1]], [[1.0, 0.0]], [[-1.0 / self.l1]])
