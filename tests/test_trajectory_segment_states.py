"""The generator's spline segment evaluated for all its steps at once gives the per-step formula to the bit, and the
hull bound that spares the exact peak speed never lets a path above the velocity limit through."""

from __future__ import annotations

import numpy as np
import pytest

from cosim.trajectory.generator import (GeneratorSettings, TrajectoryGenerator, UntrackablePathError, _peak_speed,
                                        _spline_states, _spline_weights)
from cosim.trajectory.limits import ArmLimits, JointLimits


def _one_state(points, u, period):
    """The segment's state at one ``u``, term by term on a float ``u`` (the formula the batched rows must match)."""
    w = 1.0 - u
    p0, p1, p2, p3 = points
    d0, d1, d2 = p1 - p0, p2 - p1, p3 - p2
    position = (w * w * w * p0 + (3.0 * u**3 - 6.0 * u * u + 4.0) * p1 + (1.0 + 3.0 * u + 3.0 * u * u - 3.0 * u**3) * p2 + u**3 * p3) / 6.0
    velocity = (w * w * d0 + (1.0 + 2.0 * u - 2.0 * u * u) * d1 + u * u * d2) / (2.0 * period)
    acceleration = (w * (d1 - d0) + u * (d2 - d1)) / (period * period)
    return position, velocity, acceleration


def test_the_rows_match_the_one_u_formula_bit_for_bit():
    rng = np.random.default_rng(3)
    us = [0.0, 1.0] + [k * 0.002 / 0.01 for k in range(1, 6)] + list(rng.uniform(0.0, 1.0, 20))
    for _ in range(50):
        points = rng.normal(0.0, 0.3, (4, 6))
        batch = _spline_states(points, _spline_weights(us), 0.01)
        for row, u in enumerate(us):
            for got, expected in zip((a[row] for a in batch), _one_state(points, u, 0.01)):
                assert got.tobytes() == expected.tobytes()


def test_within_the_hull_bound_the_exact_peak_is_within_the_limit():
    """The generator skips the exact peak where every control-point step is within (1 - 1e-9) max_velocity T: there
    the exact peak must be within max_velocity, including limits that put the largest step at the bound itself and
    equal steps (a constant speed, the peak equal to the hull's)."""
    rng = np.random.default_rng(5)
    period = 0.01
    for k in range(2000):
        points = np.cumsum(rng.normal(0.0, 0.01, (4, 6)), axis=0)
        if k % 3 == 0:
            points = points[0] + np.arange(4)[:, None] * (points[1] - points[0])  # equal steps
        largest = np.abs(np.diff(points, axis=0)).max(axis=0)
        # every other case: the limit whose bound is the largest step; else a limit above it
        vmax = largest / (period * (1.0 - 1e-9)) * (1.0 if k % 2 else rng.uniform(1.0, 1.5))
        while not (np.abs(np.diff(points, axis=0)) <= vmax * period * (1.0 - 1e-9)).all():  # (as the generator tests it)
            vmax = np.nextafter(vmax, np.inf)  # the smallest such limit, past the divisions' rounding
        assert (_peak_speed(points, period) <= vmax).all()


def test_a_stream_beyond_the_velocity_limit_still_raises():
    joints = tuple(JointLimits(f"arm/j{k}", 1.0, 8.0, 100.0, -3.0, 3.0) for k in range(2))
    generator = TrajectoryGenerator(ArmLimits("arm", "test", joints), np.zeros(2),
                                    GeneratorSettings(cycle_time=0.002, control_period=0.01, stop_beyond_velocity_limit=True))
    with pytest.raises(UntrackablePathError, match="joint j1"):
        for k in range(1, 50):
            generator.set_target(np.array([0.0, 0.012 * k]))  # 1.2 rad/s on j1 (limit 1)
            for _ in range(5):
                generator.step()
