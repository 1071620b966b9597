"""A jerk-limited filter that tracks a moving target: a saturated linear state-variable filter.

A time-optimal generator re-planned every period toward each new target as one to stop at (ruckig's profiles) moves
bang-bang in jerk: when the target moves every period, its path changes the sign of its jerk at the control rate.
This filter moves each coordinate as a triple integrator x''' = j with the jerk held over each period h, driven by
linear state feedback on the error to the target,

    j = K0 (r - x) - K1 v - K2 a,

whose gains place the three closed-loop poles of the sampled system at z = exp(-w h) (critically damped at w rad/s;
the control library's Ackermann formula). Unsaturated it is a linear low-pass of the target: a ramp at rate r' is
followed at the constant lag ``K1 / K0`` (about 3 / w) with no jerk at all once the start has died away, and noise
on the target is rolled off as f^-3 above w. It is written in cascade form, the same gains as three nested loops,

    v_c = K0 / K1 (r - x),   a_c = K1 / K2 (v_c - v),   j = K2 (a_c - a),

so that the commanded rate and acceleration can be saturated without winding up the outer loop: v_c is held within
the velocity limit and the speed from which the acceleration limit stops the path at the target (half of it, for
the jerk ramp), a_c within the acceleration limit.

Limits hold by construction, whatever the target: each period's jerk is clipped to the limit jerk, to the jerks
that keep the next acceleration within its limit, and to those from which the next velocity can still be brought
to rest within the velocity limit by the limit jerk (v + a |a| / (2 J) within the limit). The velocity within the
period is then within the limit too: while the acceleration keeps its sign the velocity moves toward
v + a |a| / (2 J) and no further.
"""

from __future__ import annotations

import math

import control
import numpy as np

from cosim.checks import check_positive, check_range


class TrackingFilter:
    """Saturated linear tracking of a target vector (see the module docstring), one coordinate per entry.

    velocity, acceleration, jerk: the limits per coordinate (units/s, /s^2, /s^3), each > 0; bandwidth: w (rad/s),
    the closed loop's triple pole; period: h (s), the time between calls. Starts at rest at zero."""

    def __init__(self, velocity: np.ndarray, acceleration: np.ndarray, jerk: np.ndarray, bandwidth: float, period: float):
        check_positive("tracking_filter.bandwidth", bandwidth, "rad/s", None)
        check_range("tracking_filter.period", period, 0.0, 1.0, "s", lo_open=True)
        self.velocity_limit, self.acceleration_limit, self.jerk_limit = (np.asarray(x, dtype=float) for x in (velocity, acceleration, jerk))
        self.period = float(period)
        h = self.period
        transition = np.array([[1.0, h, h * h / 2.0], [0.0, 1.0, h], [0.0, 0.0, 1.0]])
        jerk_input = np.array([[h**3 / 6.0], [h * h / 2.0], [h]])
        k0, k1, k2 = np.asarray(control.acker(transition, jerk_input, [math.exp(-bandwidth * h)] * 3)).ravel()
        self._position_gain, self._velocity_gain, self._acceleration_gain = k0 / k1, k1 / k2, k2
        self.lag = k1 / k0  # s: how far a ramp is followed behind, once the start has died away
        n = len(self.velocity_limit)
        self.position, self.velocity, self.acceleration = np.zeros(n), np.zeros(n), np.zeros(n)

    def reset(self, position: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray) -> None:
        """Continue from this state (e.g. where another generator has left the path); it must be within the limits."""
        self.position, self.velocity, self.acceleration = (np.array(x, dtype=float) for x in (position, velocity, acceleration))

    def step(self, target: np.ndarray) -> np.ndarray:
        """The position one period on, heading for ``target``."""
        h, jmax, amax, vmax = self.period, self.jerk_limit, self.acceleration_limit, self.velocity_limit
        x, v, a = self.position, self.velocity, self.acceleration
        error = np.asarray(target, dtype=float) - x
        stopping_speed = np.sqrt(amax * np.abs(error))  # from which half the acceleration limit stops at the target
        v_c = np.clip(self._position_gain * error, -np.minimum(vmax, stopping_speed), np.minimum(vmax, stopping_speed))
        a_c = np.clip(self._velocity_gain * (v_c - v), -amax, amax)
        a_next = a + h * np.clip(self._acceleration_gain * (a_c - a), -jmax, jmax)
        low, high = self._admissible_accelerations(v, a)
        a_next = np.clip(a_next, np.maximum(low, a - h * jmax), np.minimum(high, a + h * jmax))
        j = (a_next - a) / h
        self.position = x + h * v + h * h / 2.0 * a + h**3 / 6.0 * j
        self.velocity = v + h / 2.0 * (a + a_next)
        self.acceleration = a_next
        return self.position.copy()

    def _admissible_accelerations(self, v: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The range of next accelerations a' within the acceleration limit from whose next velocity
        v' = v + h (a + a') / 2 the limit jerk J can bring the rate to rest within the velocity limit V:
        v' + a' |a'| / (2 J) <= V, and >= -V by symmetry. The left side rises with a', so the bound is the root of
        a' |a'| / (2 J) + h a' / 2 = V - v - h a / 2 (a quadratic in a' on each side of zero)."""
        h, jmax, amax, vmax = self.period, self.jerk_limit, self.acceleration_limit, self.velocity_limit

        def highest(room: np.ndarray) -> np.ndarray:  # the a' with a' |a'| / (2 J) + h a' / 2 = room
            b = h / 2.0
            return np.sign(room) * jmax * (np.sqrt(b * b + 2.0 * np.abs(room) / jmax) - b)

        high = np.minimum(amax, highest(vmax - v - h * a / 2.0))
        low = np.maximum(-amax, -highest(vmax + v + h * a / 2.0))
        return low, np.maximum(high, low)
