"""What the pour controller reads each control step and what it answers.

Frames: pour plane = world x-z (x toward the pour, z up); vessel frame of the pourer: origin at the centre of its
inner floor, +x toward the pour lip, +z up its axis. Inner width B, inner height L, wall thickness t; the pour
lip is the outer top edge of the +x wall, vessel (B/2 + t, L); the crest point is its inner top edge,
vessel (B/2, L), the highest point of the wall top when the vessel tilts toward the lip. Tilt theta: rotation
about world +y, positive lowers the lip.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, fields
from enum import Enum

from controllers.errors import MeasurementError
from controllers.geometry import PlanarPose


@dataclass(frozen=True)
class LiquidMeasurement:
    """One control step's measurement, taken from the simulated liquid and the arms (SI units, rad).

    t: s, simulation time; strictly increasing from one step to the next.
    tilt: rad, the pourer's actual tilt theta = atan2(e_z.x, e_z.z), e_z = the pourer's +z axis in world.
    theta1: rad, free-surface angle of the liquid in the pourer, in the POURER'S VESSEL FRAME, positive when the
      surface stands higher at the lip wall. Measured as: take the liquid particles inside the pourer's inner box
      (vessel x in [-B/2, B/2], z in [0, L]); express them in the vessel frame; the liquid's height at the
      columns x_k = k w, k = -K..K, w = 2 dx (dx = particle spacing), K = floor((B/2 - 2 w) / w), is
      H_k = (dx^dim / w) sum_i B((x_i - x_k) / w) / D(x_i)^(dim - 2), B the cubic B-spline (support +-2 in its
      argument, unit integral), D(x) in 3-D the section's extent across the pour plane at x (a box's depth, a
      cylinder's chord); fit z = c + m x to the columns with H_k > 0 by least squares; theta1 = atan(m). Fewer
      than three such columns: theta1 = tilt (nothing to fit). A liquid at rest gives theta1 = tilt; equivalently
      theta1 = tilt + atan(dz/dx) of the same surface fitted in world x-z. Smooth in the particle positions
      (:mod:`cosim.coupling.free_surface`): no jump when another particle becomes a column's highest.
    h_q: m, height of the free surface over the crest point, along world z, read from the liquid's volume over the
      crest level: each particle spread as the cubic B-spline B (support +-2 in its argument) over x (and y in 3-D)
      with width w = 2 dx (dx = particle spacing) and over z with width dx, the volume over the crest's z per unit
      width (and depth) at the window centred w upstream of the crest's world x (and at its y) is m = dx (dx /
      w)^(dim - 1) * sum_i B(sx_i) [B(sy_i)] C(sz_i), sx, sy = (particle - window) / w, sz = (particle z - crest
      z) / dx, C the integral of B; h_q = dx * G^-1(m / dx), G the second integral of B (G(v) = v for v >= 2),
      which makes it the level of a liquid at rest, and of a particle lattice at least 2 dx over the crest its top
      particle centre + dx/2 - z of the crest (:mod:`cosim.coupling.crest_head`). Smooth in the particle positions:
      no jump when another particle becomes the highest.
      Where m = 0 (no particle within 2 dx below the crest level in the window): the height of the theta1 fit line
      above the crest along world z, clipped to <= 0 (:func:`controllers.geometry.height_above`). h_q > 0 means
      outflow.
    v_q: m/s, mean world-x velocity of the liquid particles that have just left over the lip: those outside the
      inner box with world x in [x_lip + dx, x_lip + 4 dx] and z in [z_lip - 6 dx, z_lip + dx + max(h_q, 0)] (the
      stream one to four spacings past the lip, where it already falls freely: nearer the lip the liquid behind
      still pushes it, and a launch state taken there predicts a landing 4-5 mm short); 0 when there are none.
    volume_in_pourer: m^3, liquid inside the pourer's inner box.
    poured_volume: m^3, liquid that has left the pourer since the start (initial minus in-pourer volume).
    lip_x, lip_z: m, world position of the pour lip (outer top edge of the +x wall).
    catcher_rim_z: m, world z of vessel B's rim, the height at which the jet enters it.
    v_q_z: m/s, mean world-z velocity (up positive) of the same particles as v_q; 0 reproduces the paper's
      Eq. 6 (Camporredondo et al. 2019).
    jet_dx, jet_dz: m, mean world position of the same particles relative to the lip: where the measured launch
      state (v_q, v_q_z) applies; 0 launches at the lip (the paper's Eqs. 6-7).
    """

    t: float
    tilt: float
    theta1: float
    h_q: float
    v_q: float
    volume_in_pourer: float
    poured_volume: float
    lip_x: float
    lip_z: float
    catcher_rim_z: float
    v_q_z: float = 0.0
    jet_dx: float = 0.0
    jet_dz: float = 0.0

    def __post_init__(self) -> None:
        for name in _MEASUREMENT_FIELDS:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise MeasurementError(f"measurement.{name}: must be a finite number, got {value!r}")
        for name in ("volume_in_pourer", "poured_volume"):
            if getattr(self, name) < 0.0:
                raise MeasurementError(f"measurement.{name}: must be >= 0 m^3, got {getattr(self, name):g}")

    @property
    def slosh_angle(self) -> float:
        """sigma = theta1 - tilt (rad): the free surface's angle to the world horizontal, + when higher toward +x."""
        return self.theta1 - self.tilt


_MEASUREMENT_FIELDS = tuple(f.name for f in fields(LiquidMeasurement))  # read once: each control step checks them all


class Phase(Enum):
    """Phases of a pour, in the order a pour passes them (SIM phases or APPROACH, not both)."""

    IDLE = "idle"  # at home until start_time; vessel B pre-positioned
    SIM_EXCITE = "sim_excite"  # t0: theta = phi sin(alpha t) about the floor centre
    SIM_HOLD = "sim_hold"  # t1: hold phi until the slosh angle crosses zero toward the lip
    SIM_DAMP = "sim_damp"  # t2: filtered PID on theta1
    APPROACH = "approach"  # without SIM: rate-limited tilt toward the crest about the pendulum hinge
    CFS = "cfs"  # constant flow: h_q held at its reference, about the lip
    CFS_FINAL = "cfs_final"  # a partial pour's last part: CFS at a lower h_q reference, so that it stops cleanly
    RETURN = "return"  # back upright and home, rate-limited
    DONE = "done"


@dataclass(frozen=True)
class PhaseTransition:
    """A phase change at time t (s) and why."""

    t: float
    source: Phase
    target: Phase
    reason: str


# A command's path ahead where the controller knows it (an analytic command): ``tau`` s ahead (s) -> the target pose.
PoseAhead = Callable[[float], PlanarPose]


@dataclass(frozen=True)
class PourCommand:
    """The controller's answer for one step.

    pourer: target pose of the pourer relative to its home (dx, dz in m, theta in rad; see
      :class:`controllers.geometry.PlanarPose`).
    catcher: target pose of vessel B relative to its home, (dx, 0, 0).
    phase, reason: the current phase and why it started.
    landing_x: m, world x where the jet is predicted to cross vessel B's rim (Eqs. 6-7), vessel B's target.
      Before the outflow starts: the prediction for the weir velocity at h_q_ref from the current lip. Once the
      pour is over (return, done) and nothing flows: the last target, held.
    slosh_angle: rad, the measured sigma = theta1 - tilt.
    feedback: the pourer's target is a feedback command whose timing matters (the slosh damping, SIM_DAMP), already
      smoothed by the controller (:class:`controllers.motion.CriticallyDampedSmoother`): it goes to the arm without
      further smoothing lag.
    pourer_ahead: the pourer's target ``tau`` s ahead, where the command is analytic (the slosh induction's
      excitation and the hold it ends in), so that a stage that delays the path can be fed it that much early;
      None elsewhere.
    """

    t: float
    pourer: PlanarPose
    catcher: PlanarPose
    phase: Phase
    reason: str
    landing_x: float
    slosh_angle: float
    feedback: bool = False
    pourer_ahead: PoseAhead | None = None

    @property
    def done(self) -> bool:
        return self.phase is Phase.DONE
