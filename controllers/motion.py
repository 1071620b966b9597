"""Rate- and acceleration-limited 1-D tracking: moves a coordinate toward a target without large steps; a
jerk-limited move to rest; and the delay of a follower behind its command.

Used for the catcher's position (m), the approach tilt (rad) and, jerk-limited, the return tilt (rad). Units follow
the coordinate: ``max_rate`` per second, ``max_accel`` per second squared, ``max_jerk`` per second cubed, ``dt`` in s.
"""

from __future__ import annotations

import math

import numpy as np
import ruckig

from declared_settings.setting import argument

# The building blocks' arguments, declared once (the configurations that build them declare their own, narrower
# ranges); a limit's unit is the coordinate's per second, per second squared or per second cubed.
MOTION = "motion"
MAX_RATE = argument(MOTION, "Rate limit, the coordinate's unit per second.", "", 0.0, None, lo_open=True)
MAX_ACCEL = argument(MOTION, "Acceleration limit, the coordinate's unit per second squared.", "", 0.0, None,
                     lo_open=True)
MAX_JERK = argument(MOTION, "Jerk limit, the coordinate's unit per second cubed.", "", 0.0, None, lo_open=True)
STOP_ACCEL = argument(MOTION, "Acceleration limit in the direction that slows a move toward its target.", "", 0.0,
                      "max_accel", lo_open=True)
TIME_STEP = argument(MOTION, "Sample time.", "s", 0.0, 1.0, lo_open=True)
BANDWIDTH = argument(MOTION, "Each low-pass's corner frequency, 1 / its time constant.", "rad/s", 0.0, None,
                     lo_open=True)
STAGES = argument(MOTION, "First-order low-passes in series.", "", 1, None, kind="int")


class RateLimitedTracker:
    """Discrete second-order tracker: each step the velocity moves by at most max_accel dt toward the
    velocity that would stop exactly at the target under max_accel, itself capped by max_rate."""

    def __init__(self, max_rate: float, max_accel: float, dt: float, position: float = 0.0) -> None:
        self.max_rate = MAX_RATE.check("tracker.max_rate", max_rate)
        self.max_accel = MAX_ACCEL.check("tracker.max_accel", max_accel)
        self.dt = TIME_STEP.check("tracker.dt", dt)
        self.position = float(position)
        self.velocity = 0.0

    def reset(self, position: float, velocity: float = 0.0) -> None:
        self.position, self.velocity = float(position), float(velocity)

    def step(self, target: float) -> float:
        """Advance one step toward ``target``; returns the new position."""
        err, a, dt = target - self.position, self.max_accel, self.dt
        # Largest speed v from which braking by a dt per step stops within |err|: v^2/(2a) + v dt/2 = |err|.
        stop_speed = a * (math.sqrt(0.25 * dt * dt + 2.0 * abs(err) / a) - 0.5 * dt)
        want = math.copysign(min(self.max_rate, stop_speed, abs(err) / dt), err)
        self.velocity = min(max(want, self.velocity - a * dt), self.velocity + a * dt)
        self.position += self.velocity * dt
        return self.position

    def at(self, target: float, tol: float) -> bool:
        """True when within ``tol`` of ``target`` and (almost) at rest."""
        return abs(target - self.position) <= tol and abs(self.velocity) <= self.max_accel * self.dt


class JerkLimitedMove:
    """The time-optimal move of one coordinate from ``position`` at ``velocity`` (and zero acceleration) to rest at
    ``target`` within rate, acceleration and jerk limits (ruckig's profile): continuous in acceleration, so a
    follower with finite jerk can stay on it. The acceleration stays within [-max_accel, max_accel], and within
    ``stop_accel`` (default max_accel) in the direction that slows a move toward the target (so a move can set
    off briskly and stop gently). :meth:`at` samples it at a time (s) since the start."""

    def __init__(self, position: float, velocity: float, target: float, max_rate: float, max_accel: float,
                 max_jerk: float, stop_accel: float | None = None) -> None:
        MAX_RATE.check("move.max_rate", max_rate)
        self.max_accel = MAX_ACCEL.check("move.max_accel", max_accel)
        MAX_JERK.check("move.max_jerk", max_jerk)
        stop = max_accel if stop_accel is None else STOP_ACCEL.check("move.stop_accel", stop_accel, self)
        inp = ruckig.InputParameter(1)
        inp.current_position, inp.current_velocity, inp.current_acceleration = [position], [velocity], [0.0]
        inp.target_position, inp.target_velocity, inp.target_acceleration = [target], [0.0], [0.0]
        inp.max_velocity, inp.max_jerk = [max_rate], [max_jerk]
        # toward a lower target the stop accelerates upward: the upper bound is the stop's, and the other way round
        down = target < position
        inp.max_acceleration, inp.min_acceleration = ([stop], [-max_accel]) if down else ([max_accel], [-stop])
        self._trajectory = ruckig.Trajectory(1)
        # the start's rate lies within max_rate (a return starts from the pour's slow tilt rate): always solvable
        ruckig.Ruckig(1).calculate(inp, self._trajectory)
        self.target = float(target)

    @property
    def duration(self) -> float:
        """s, until at rest on the target."""
        return float(self._trajectory.duration)

    def at(self, t: float) -> float:
        """Position at ``t`` s after the start (the target from :attr:`duration` on)."""
        if t >= self.duration:
            return self.target
        return float(self._trajectory.at_time(max(t, 0.0))[0][0])


class CriticallyDampedSmoother:
    """``stages`` first-order low-passes in series at a fixed sample time: y1 += a (x - y1), y_k += a (y_{k-1} - y_k),
    a = 1 - exp(-bandwidth dt); output the last. A linear, amplitude-independent smoother (unlike a limit-based one),
    whose transfer function (:meth:`transfer_function_coefficients`) a feedback design can include: its
    low-frequency delay is stages / bandwidth and its output's acceleration stays bounded for bounded input steps.
    Its impulse response is positive with unit sum, so its output's differences of any order are never larger than
    the input's largest (what limits a path's sampled rates holds after it). ``bandwidth`` (:data:`BANDWIDTH`),
    ``dt`` (:data:`TIME_STEP`), ``stages`` (:data:`STAGES`, default 2); units of x and y are the caller's.
    """

    def __init__(self, bandwidth: float, dt: float, stages: int = 2) -> None:
        BANDWIDTH.check("smoother.bandwidth", bandwidth)
        TIME_STEP.check("smoother.dt", dt)
        STAGES.check("smoother.stages", stages)
        self.gain = 1.0 - math.exp(-bandwidth * dt)
        self.dt = float(dt)
        self._stages = [0.0] * int(stages)

    @property
    def delay(self) -> float:
        """s, how far the output lags a ramp once the start has died away: ``(1 - a) / a`` periods per stage."""
        return len(self._stages) * (1.0 - self.gain) / self.gain * self.dt

    def reset(self, value: float, rate: float = 0.0) -> None:
        """Every stage as on a ramp at ``rate`` (units/s; 0: at rest) whose output is ``value`` now: each stage ahead
        of the next by the ramp's lag through one stage, ``rate (1 - a) / a dt``."""
        lag = rate * (1.0 - self.gain) / self.gain * self.dt
        n = len(self._stages)
        self._stages = [float(value) + (n - 1 - k) * lag if lag else float(value) for k in range(n)]

    def step(self, x: float) -> float:
        """One sample of input ``x``; returns the smoothed output."""
        for k, y in enumerate(self._stages):
            self._stages[k] = y + self.gain * (x - y)
            x = self._stages[k]
        return x

    def transfer_function_coefficients(self) -> tuple[list[float], list[float]]:
        """(numerator, denominator) in z, highest power first: a^n z^n / (z - (1 - a))^n, n the stages."""
        a, n = self.gain, len(self._stages)
        return [a**n] + [0.0] * n, np.poly([1.0 - a] * n).tolist()


def stop_time(distance: float, max_rate: float, max_accel: float) -> float:
    """Time (s) to travel ``distance`` from rest with the rate and acceleration limits (accelerate, cruise)."""
    d = abs(distance)
    if d <= 0.5 * max_rate * max_rate / max_accel:
        return math.sqrt(2.0 * d / max_accel)
    return d / max_rate + 0.5 * max_rate / max_accel


def fitted_delay(t: np.ndarray, command: np.ndarray, response: np.ndarray, max_delay: float, resolution: float) -> float:
    """Delay L (s) for which response(t) best matches command(t - L), by least squares over L in [0, max_delay].

    ``t``: sample times (s, increasing), shared by the two series; command(t - L) is interpolated linearly, held at
    its first value before t[0]. The grid of candidate delays has step ``resolution`` (s). A command that does not
    move leaves the delay undetermined: the smallest best-fitting delay is returned, 0 for a constant command.
    """
    delays = np.arange(0.0, max_delay + 0.5 * resolution, resolution)
    shifted = np.interp(t[None, :] - delays[:, None], t, command)
    cost = np.sum((shifted - response[None, :]) ** 2, axis=1)
    return float(delays[int(np.argmin(cost))])
