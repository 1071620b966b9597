"""A filter that tracks a moving target within rate, acceleration and jerk limits: a linear state-variable filter.

A time-optimal generator re-planned every period toward each new target as one to stop at (ruckig's profiles) moves
bang-bang in jerk: when the target moves every period, its path changes the sign of its jerk at the control rate.
This filter moves each coordinate as a triple integrator x''' = j with the jerk held over each period h, driven by
linear state feedback on the error to the target,

    j = K0 (r - x) - K1 v - K2 a,

whose gains place the three closed-loop poles of the sampled system at z = exp(-w h) (critically damped at w rad/s;
the control library's Ackermann formula). It is a linear low-pass of the target: a ramp at rate r' is followed at
the constant lag ``K1 / K0`` (about 3 / w) with no jerk at all once the start has died away, and noise on the target
is rolled off as f^-3 above w.

A linear law cannot follow a step within a jerk limit far below w^3 times the step (at 35 rad/s and 20 rad/s^3, any
step over half a milliradian): clipped to the limits, the integrator chain winds up and overshoots (0.02-1 rad steps by 13 % to
several times the step, in cascade form with or without the commanded rate and acceleration saturated as well). So a path moves by the
linear law where its jerk is admissible (:meth:`TrackingFilter.limited_step`), by the law clipped to the limits
where it asks a little more (:meth:`TrackingFilter.clipped_step`, :meth:`TrackingFilter.saturation`), and otherwise
by a time-optimal generator heading for the law's steady motion: the target less the lag times the rate of the
law's own unlimited path (:meth:`TrackingFilter.follow`), at that rate (:class:`cosim.coupling.pose_filter.PoseFilter`).

Limits hold by construction, from a state within them: a linear step is taken only with a jerk within the limit
jerk, a next acceleration within its limit, and a next state from which the limit jerk can still bring the
velocity to a stop within the velocity limit less a margin of J h^2 / 8,
v + a |a| / (2 J) <= V - J h^2 / 8 (and >= its negative). Within a period the acceleration is linear and the velocity
monotone unless the acceleration changes sign; where it does at a jerk |j| < J, the velocity peaks
a^2 (J - |j|) / (2 |j| J) <= J h^2 / 8 above v + a |a| / (2 J): the margin. So the velocity, acceleration and jerk
stay within the limits at every instant, and so do the sampled path's mean rates.
"""

from __future__ import annotations

import math

import numpy as np

from controllers.motion import TIME_STEP
from declared_settings.setting import argument

# The closed loop's triple pole w (the filter's period is a time step, controllers.motion.TIME_STEP).
BANDWIDTH = argument("tracking filter", "Triple pole of the sampled closed loop, z = exp(-w h).", "rad/s", 0.0, None,
                     lo_open=True)


class TrackingFilter:
    """Linear tracking of a target vector within limits (see the module docstring), one coordinate per entry.

    velocity, acceleration, jerk: the limits per coordinate (units/s, /s^2, /s^3), each > 0; bandwidth: w
    (:data:`BANDWIDTH`); period: h, the time between calls (:data:`controllers.motion.TIME_STEP`). The path's state is
    the caller's."""

    def __init__(self, velocity: np.ndarray, acceleration: np.ndarray, jerk: np.ndarray, bandwidth: float, period: float):
        import control  # here, so that reading a scene and refusing bad input stay fast
        BANDWIDTH.check("tracking_filter.bandwidth", bandwidth)
        TIME_STEP.check("tracking_filter.period", period)
        self.velocity_limit, self.acceleration_limit, self.jerk_limit = (np.asarray(x, dtype=float) for x in (velocity, acceleration, jerk))
        self.period = float(period)
        h = self.period
        transition = np.array([[1.0, h, h * h / 2.0], [0.0, 1.0, h], [0.0, 0.0, 1.0]])
        jerk_input = np.array([[h**3 / 6.0], [h * h / 2.0], [h]])
        k0, k1, k2 = np.asarray(control.acker(transition, jerk_input, [math.exp(-bandwidth * h)] * 3)).ravel()
        self._gains = (k0, k1, k2)
        self.lag = k1 / k0  # s: how far the state follows a ramp behind, once the start has died away
        n = len(self.velocity_limit)
        self.reference = (np.zeros(n), np.zeros(n), np.zeros(n))  # the law's own path, unlimited
        self._last_step: tuple[bytes, tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None  # _linear_step's last

    def follow(self, target: np.ndarray, state: tuple[np.ndarray, np.ndarray, np.ndarray] | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance the law's own unlimited path one period toward ``target`` (from ``state`` where given: the
        limited path, where it moves by the law); returns it. Its velocity is the target's rate low-passed by the
        law, an estimate without the target's step-to-step noise."""
        self.reference = self._linear_step(target, *(state if state is not None else self.reference))
        return self.reference

    def saturation(self, target: np.ndarray, position: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray) -> float:
        """The linear law's jerk from a path's state toward ``target`` over the jerk limit, the largest over the
        coordinates: how far it would saturate."""
        jerk = (self._linear_step(target, position, velocity, acceleration)[2] - acceleration) / self.period
        return float(np.max(np.abs(jerk) / self.jerk_limit))

    def limited_step(
        self, target: np.ndarray, position: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The state one period on from a path's state by the linear law toward ``target``, or None where its
        jerk would break a limit (the module docstring)."""
        state = self._linear_step(target, position, velocity, acceleration)
        low, high = self._admissible_range(velocity, acceleration)
        if (state[2] < low).any() or (state[2] > high).any():
            return None
        return state

    def clipped_step(
        self, target: np.ndarray, position: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The state one period on from a path's state by the linear law toward ``target`` with its jerk clipped to
        the admissible range (the module docstring)."""
        a_next = np.clip(self._linear_step(target, position, velocity, acceleration)[2], *self._admissible_range(velocity, acceleration))
        return self._advance(position, velocity, acceleration, a_next)

    def _admissible_range(self, velocity: np.ndarray, acceleration: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The next accelerations within the jerk limit and :meth:`_admissible_accelerations`."""
        low, high = self._admissible_accelerations(velocity, acceleration)
        step = self.period * self.jerk_limit
        return np.minimum(np.maximum(low, acceleration - step), acceleration + step), np.minimum(high, acceleration + step)

    def _linear_step(self, target, x, v, a) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The state one period on by the linear law's jerk, unlimited. A period's calls ask for it up to four times
        from one state (the limited step, the saturation, the clipped step, the law's own path): it is computed once
        per state and target, recognised by their bytes."""
        target, x, v, a = (np.asarray(q, dtype=float) for q in (target, x, v, a))
        key = target.tobytes() + x.tobytes() + v.tobytes() + a.tobytes()
        if self._last_step is not None and self._last_step[0] == key:
            return self._last_step[1]
        j = self._gains[0] * (target - x) - self._gains[1] * v - self._gains[2] * a
        step = self._advance(x, v, a, a + self.period * j)
        self._last_step = (key, step)
        return step

    def _advance(self, x, v, a, a_next) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The state one period on with the jerk (a_next - a) / h held over the period."""
        h = self.period
        return x + h * v + h * h / 2.0 * a + h * h / 6.0 * (a_next - a), v + h / 2.0 * (a + a_next), a_next

    def _admissible_accelerations(self, v: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The range of next accelerations a' within the acceleration limit from whose next velocity
        v' = v + h (a + a') / 2 the limit jerk J can bring the rate to rest within the velocity limit less its
        margin, V = limit - J h^2 / 8: v' + a' |a'| / (2 J) <= V, and >= -V by symmetry. The left side rises with
        a', so the bound is the root of a' |a'| / (2 J) + h a' / 2 = V - v - h a / 2 (a quadratic in a' on each
        side of zero)."""
        h, jmax, amax, vmax = self.period, self.jerk_limit, self.acceleration_limit, self.velocity_limit

        def highest(room: np.ndarray) -> np.ndarray:  # the a' with a' |a'| / (2 J) + h a' / 2 = room
            b = h / 2.0
            return np.sign(room) * jmax * (np.sqrt(b * b + 2.0 * np.abs(room) / jmax) - b)

        speed = vmax - jmax * h * h / 8.0  # the margin for the velocity's peak inside a period
        high = np.minimum(amax, highest(speed - v - h * a / 2.0))
        low = np.maximum(-amax, -highest(speed + v + h * a / 2.0))
        return low, np.maximum(high, low)
