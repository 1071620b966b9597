"""Rate- and acceleration-limited 1-D tracking: moves a coordinate toward a target without large steps.

Used for the catcher's position (m), the approach tilt and the return tilt (rad). Units follow the coordinate:
``max_rate`` per second, ``max_accel`` per second squared, ``dt`` in s.
"""

from __future__ import annotations

import math

from controllers.checks import check_range


class RateLimitedTracker:
    """Discrete second-order tracker: each step the velocity moves by at most max_accel dt toward the
    velocity that would stop exactly at the target under max_accel, itself capped by max_rate."""

    def __init__(self, max_rate: float, max_accel: float, dt: float, position: float = 0.0) -> None:
        self.max_rate = check_range("tracker.max_rate", max_rate, 0.0, None, lo_open=True)
        self.max_accel = check_range("tracker.max_accel", max_accel, 0.0, None, lo_open=True)
        self.dt = check_range("tracker.dt", dt, 0.0, 1.0, "s", lo_open=True)
        self.position = float(position)
        self.velocity = 0.0

    def reset(self, position: float, velocity: float = 0.0) -> None:
        self.position, self.velocity = float(position), float(velocity)

    def step(self, target: float) -> float:
        """Advance one step toward ``target``; returns the new position."""
        err = target - self.position
        # Speed from which max_accel still stops at the target; the discrete term keeps the last steps exact.
        stop_speed = math.sqrt(2.0 * self.max_accel * abs(err))
        want = math.copysign(min(self.max_rate, stop_speed, abs(err) / self.dt), err)
        dv = self.max_accel * self.dt
        self.velocity = min(max(want, self.velocity - dv), self.velocity + dv)
        self.position += self.velocity * self.dt
        return self.position

    def at(self, target: float, tol: float) -> bool:
        """True when within ``tol`` of ``target`` and (almost) at rest."""
        return abs(target - self.position) <= tol and abs(self.velocity) <= self.max_accel * self.dt


def stop_time(distance: float, max_rate: float, max_accel: float) -> float:
    """Time (s) to travel ``distance`` from rest with the rate and acceleration limits (accelerate, cruise)."""
    d = abs(distance)
    if d <= 0.5 * max_rate * max_rate / max_accel:
        return math.sqrt(2.0 * d / max_accel)
    return d / max_rate + 0.5 * max_rate / max_accel
