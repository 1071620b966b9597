"""The smoothness figures on synthetic trajectories with known content: a 2 Hz sine passes, the same with a 30 Hz
ripple fails; the high-frequency RMS equals the ripple's known RMS, the sign changes the ripple's known count."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.smoothness import JERK_DEAD_BAND, acceleration_rms_above, jerk_sign_changes, trajectory_smoothness

RATE = 500.0  # Hz, the exported sampling
DURATION = 4.0  # s
SLOW_HZ, SLOW_AMPLITUDE = 2.0, 0.005  # rad: a pour-like motion (acceleration amplitude 0.79, jerk 9.9 rad/s^3)
RIPPLE_HZ, RIPPLE_ACCELERATION = 30.0, 0.1  # Hz, rad/s^2 amplitude: a chatter (RMS 0.071 rad/s^2)
# The acceptance a smooth trajectory meets: acceleration RMS above 10 Hz and jerk sign changes per second.
SMOOTH_RMS, SMOOTH_CHANGES = 0.02, 10.0
# The method's own error (leakage of slow motion into the high band, see cosim.trajectory.smoothness) must stay
# below a tenth of the acceptance on motions the size of a pour's.
LEAKAGE = 0.1 * SMOOTH_RMS


def _trajectory(ripple: bool) -> JointTrajectory:
    """Two joints moving as a 2 Hz sine over whole periods, the second with or without a 30 Hz acceleration
    ripple."""
    t = np.arange(int(DURATION * RATE) + 1) / RATE
    w, r = 2.0 * math.pi * SLOW_HZ, 2.0 * math.pi * RIPPLE_HZ
    q = SLOW_AMPLITUDE * np.sin(w * t)
    qd = SLOW_AMPLITUDE * w * np.cos(w * t)
    qdd = -SLOW_AMPLITUDE * w * w * np.sin(w * t)
    extra = RIPPLE_ACCELERATION * np.sin(r * t) if ripple else np.zeros_like(t)
    positions = np.column_stack([q, q - extra / (r * r)])
    velocities = np.column_stack([qd, qd - RIPPLE_ACCELERATION * np.cos(r * t) / r * ripple])
    accelerations = np.column_stack([qdd, qdd + extra])
    return JointTrajectory(t, ("arm/a", "arm/b"), positions, velocities, accelerations)


def test_a_slow_sine_is_smooth():
    report = trajectory_smoothness(_trajectory(ripple=False))["arm"]
    for joint in ("a", "b", "worst"):
        assert report[joint]["acceleration_rms_above_10hz"] <= LEAKAGE
        # the jerk of a sine changes sign twice a period: 4 per second at 2 Hz
        assert report[joint]["jerk_sign_changes_per_s"] == 2 * SLOW_HZ


def test_a_ripple_is_measured_at_its_known_size():
    report = trajectory_smoothness(_trajectory(ripple=True))["arm"]
    ripple_rms = RIPPLE_ACCELERATION / math.sqrt(2.0)
    assert report["b"]["acceleration_rms_above_10hz"] == pytest.approx(ripple_rms, rel=0.01)
    assert report["b"]["acceleration_rms_above_10hz"] > SMOOTH_RMS
    # the ripple's jerk (amplitude 2 pi 30 x 0.1 = 19 rad/s^3) is larger than the slow one (9.9 rad/s^3): the sum
    # changes sign with the ripple, 60 times a second
    assert report["b"]["jerk_sign_changes_per_s"] == pytest.approx(2 * RIPPLE_HZ, rel=0.02)
    assert report["b"]["jerk_sign_changes_per_s"] > SMOOTH_CHANGES
    assert report["worst"] == report["b"]
    assert report["a"]["acceleration_rms_above_10hz"] <= LEAKAGE


def test_an_unfinished_period_does_not_leak_into_the_high_band():
    """A 2 Hz acceleration of 1 rad/s^2 cut mid-period (its ends at different values and slopes): the end trend's
    subtraction removes the jump and the kink the FFT would see."""
    t = np.arange(int(1.3 * RATE)) / RATE
    a = np.sin(2.0 * math.pi * SLOW_HZ * t + 0.4)[:, None]
    assert acceleration_rms_above(a, RATE)[0] <= LEAKAGE
    high = np.fft.rfftfreq(len(t), 1.0 / RATE)[:, None] > 10.0
    naive = np.sqrt(np.mean(np.fft.irfft(np.where(high, np.fft.rfft(a, axis=0), 0.0), len(t), axis=0) ** 2))
    assert naive > 10 * acceleration_rms_above(a, RATE)[0]  # what the subtraction is for


def test_jerk_noise_inside_the_dead_band_is_not_counted():
    jerk = np.array([1.0, 0.5 * JERK_DEAD_BAND, -0.5 * JERK_DEAD_BAND, 0.3, -2.0 * JERK_DEAD_BAND, 0.0, 1.0])[:, None]
    assert jerk_sign_changes(jerk)[0] == 2  # + (noise) + then -, then +
