"""The interception search's path extrapolation in plain floats gives numpy's array arithmetic to the bit
(the generator calls it up to a dozen times per target; the pour's trajectories must not change with it)."""

from __future__ import annotations

import numpy as np

from cosim.trajectory.generator import TrajectoryGenerator, _clip
from cosim.trajectory.limits import ArmLimits, JointLimits


def _numpy_predict(path, lo, hi, vmax, jmax, tau):
    """The array expressions the float version replaces."""
    q, qd, qdd = path
    vel = np.clip(qd + qdd * tau, -vmax, vmax)
    pos = q + qd * tau + 0.5 * qdd * tau * tau
    outside = (pos < lo) | (pos > hi)
    acc = np.where((qdd > 0.0) & (vel + qdd * qdd / (2.0 * jmax) > vmax), np.sqrt(2.0 * jmax * (vmax - vel)), qdd)
    acc = np.where((qdd < 0.0) & (vel - qdd * qdd / (2.0 * jmax) < -vmax), -np.sqrt(2.0 * jmax * (vmax + vel)), acc)
    return np.clip(pos, lo, hi), np.where(outside, 0.0, vel), np.where(outside, 0.0, acc)


def test_clip_breaks_ties_as_numpy():
    for x, lo, hi in [(-0.0, 0.0, 1.0), (0.0, -0.0, 1.0), (-0.0, -1.0, 0.0), (0.0, -1.0, -0.0), (2.0, -1.0, 1.0), (-2.0, -1.0, 1.0), (0.3, -1.0, 1.0)]:
        expected = np.clip(np.array([x]), np.array([lo]), np.array([hi]))[0]
        assert np.array([_clip(x, lo, hi)]).tobytes() == np.array([expected]).tobytes()


def test_predict_matches_the_array_arithmetic_bit_for_bit():
    joints = tuple(JointLimits(f"arm/j{k}", 1.0 + 0.3 * k, 4.0, 40.0, -1.5 - 0.1 * k, 1.2 + 0.1 * k) for k in range(6))
    limits = ArmLimits("arm", "test", joints)
    generator = TrajectoryGenerator(limits, np.zeros(6))
    lo, hi, vmax = limits.array("min_position"), limits.array("max_position"), limits.array("max_velocity")
    jmax = limits.array("max_jerk")
    rng = np.random.default_rng(7)
    for _ in range(500):
        path = (rng.uniform(-1.6, 1.6, 6), rng.uniform(-2.0, 2.0, 6) * rng.integers(0, 2, 6), rng.uniform(-6.0, 6.0, 6))
        generator._path = path
        generator._path_floats = tuple(a.tolist() for a in path)
        tau = float(rng.choice([0.01, 0.3, rng.uniform(0.0, 0.3)]))
        for got, expected in zip(generator._predict(tau), _numpy_predict(path, lo, hi, vmax, jmax, tau)):
            assert np.array(got).tobytes() == expected.tobytes()
