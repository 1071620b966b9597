"""The tracking filter in the pose filter: a ramp is followed at a constant lag with no jerk once settled, steps and
noise never take the path beyond its limits; the linear step is declined where it would, the clipped one is within
them; the pose filter hands its state over to and from tracking without a jump."""

import numpy as np

from cosim.coupling.pose_filter import TRACKING_BANDWIDTH, PoseFilter, PoseFilterLimits
from cosim.coupling.tracking_filter import TrackingFilter
from cosim.robots.planar import PlanarPose
from cosim.trajectory.smoothness import jerk_sign_changes

PERIOD = 0.01  # s, the control period
LIMITS = PoseFilterLimits()
VELOCITY, ACCELERATION, JERK = LIMITS.tilt_velocity, LIMITS.tilt_acceleration, LIMITS.tilt_jerk
RAMP_RATE = 0.1  # rad/s, a CFS tilt rate
SETTLED = 1.5  # s: the start has died away


def _pose_filter() -> PoseFilter:
    return PoseFilter("pourer_pose", ("dx", "dz", "theta"), LIMITS, PERIOD)


def _tilts(f: PoseFilter, targets: np.ndarray, track: np.ndarray) -> np.ndarray:
    return np.array([f(PlanarPose(0.0, 0.0, float(r)), track=bool(k)).theta for r, k in zip(targets, track)])


def _assert_within_limits(x: np.ndarray) -> None:
    """The sampled path's rate, acceleration and jerk (differences from rest at zero) within the tilt limits."""
    rate = np.diff(np.concatenate([[0.0, 0.0, 0.0], x])) / PERIOD
    acceleration = np.diff(rate) / PERIOD
    assert np.max(np.abs(rate)) <= VELOCITY * (1 + 1e-9)
    assert np.max(np.abs(acceleration)) <= ACCELERATION * (1 + 1e-9)
    assert np.max(np.abs(np.diff(acceleration) / PERIOD)) <= JERK * (1 + 1e-9)


def test_a_ramp_is_followed_at_the_constant_lag_with_no_jerk_sign_change() -> None:
    t = np.arange(1, 301) * PERIOD
    f = _pose_filter()
    x = _tilts(f, RAMP_RATE * t, np.ones_like(t))
    lag = TrackingFilter(np.ones(1), np.ones(1), np.ones(1), TRACKING_BANDWIDTH, PERIOD).lag
    assert 0.07 < lag < 0.1  # about 3 / w at 35 rad/s
    settled = t >= SETTLED
    # each call returns the pose one period after its target's time: one period less behind that target
    np.testing.assert_allclose(RAMP_RATE * t[settled] - x[settled], RAMP_RATE * (lag - PERIOD), rtol=1e-6)
    jerk = np.diff(x, 3) / PERIOD**3
    assert jerk_sign_changes(jerk[settled[3:], None])[0] == 0
    _assert_within_limits(x)


def test_a_step_is_reached_within_the_limits_with_a_bounded_overshoot() -> None:
    """Steps the linear law cannot take within the jerk limit go by the jerk-limited generator toward the law's
    steady motion at its rate estimate, which a step makes large: the path overshoots (measured: 7 % of a 5 mrad
    step, 96 % of 20 mrad, 1.3 % of 0.2 rad, 0.2 % of 1 rad), and arrives."""
    for step, overshoot in ((0.001, 0.0), (0.005, 0.1), (0.02, 1.0), (0.2, 0.02), (1.0, 0.01)):
        x = _tilts(_pose_filter(), np.full(400, step), np.ones(400))
        assert np.max(x) <= step * (1 + overshoot) + 1e-12
        assert abs(x[-1] - step) < 1e-6 * step
        _assert_within_limits(x)


def test_limits_hold_on_a_noisy_target_and_a_slightly_noisy_one_is_tracked() -> None:
    """A slow sinusoid with noise on every target: +-3 mrad (far beyond what the CFS law sends: the path is then
    moved by the jerk-limited generator most of the time, and lags), and +-0.1 mrad (tracked linearly)."""
    rng = np.random.default_rng(3)
    t = np.arange(1, 1001) * PERIOD
    heavy = _tilts(_pose_filter(), 0.3 * np.sin(2.0 * t) + rng.uniform(-3e-3, 3e-3, len(t)), np.ones_like(t))
    _assert_within_limits(heavy)
    light = _tilts(_pose_filter(), 0.3 * np.sin(2.0 * t) + rng.uniform(-1e-4, 1e-4, len(t)), np.ones_like(t))
    _assert_within_limits(light)
    # after the start (a 0.6 rad/s rate step, taken by the jerk-limited generator), within 15 mrad of the sinusoid delayed by 0.1 s (the linear law's phase lag at 2 rad/s is 0.086 s)
    settled = t >= 3.0
    assert np.max(np.abs(light - 0.3 * np.sin(2.0 * (t - 0.1)))[settled]) < 0.015


def test_a_linear_step_beyond_the_limits_is_declined_and_a_clipped_one_is_within_them() -> None:
    f = TrackingFilter(np.array([VELOCITY]), np.array([ACCELERATION]), np.array([JERK]), TRACKING_BANDWIDTH, PERIOD)
    rest = (np.zeros(1), np.zeros(1), np.zeros(1))
    assert f.limited_step(np.array([0.2]), *rest) is None
    assert f.limited_step(np.array([1e-4]), *rest) is not None
    x, v, a = f.clipped_step(np.array([0.2]), *rest)
    np.testing.assert_allclose([x[0], v[0], a[0]], [JERK * PERIOD**3 / 6, JERK * PERIOD**2 / 2, JERK * PERIOD], rtol=1e-12)
    fast = (np.zeros(1), np.array([VELOCITY - 1e-3]), np.array([0.5]))  # must brake now to stay within V
    _, v, a = f.clipped_step(np.array([10.0]), *fast)
    assert v[0] + a[0] * abs(a[0]) / (2 * JERK) <= VELOCITY


def test_pose_filter_hands_its_state_to_and_from_tracking_without_a_jump() -> None:
    """Jerk-limited, then tracking (as in CFS), then jerk-limited again: the sampled jerk stays within the limit
    across both switches."""
    k = np.arange(300)
    x = _tilts(_pose_filter(), 0.3 + RAMP_RATE * k * PERIOD, (k >= 100) & (k < 200))
    _assert_within_limits(x)


def test_the_linear_step_made_once_per_state_is_the_one_made_anew():
    """The law's step, kept for a repeated state and target, is what a filter that never saw them computes, to the
    bit; a state changed in place (the same arrays) is a new state."""
    def fresh() -> TrackingFilter:
        return TrackingFilter(np.array([VELOCITY]), np.array([ACCELERATION]), np.array([JERK]), TRACKING_BANDWIDTH, PERIOD)

    used = fresh()
    target, state = np.array([1e-5]), (np.array([0.0]), np.array([0.0]), np.array([0.0]))
    first = used.limited_step(target, *state)
    assert first is not None
    again = used.follow(target, state)  # the same state and target: the kept step
    expected = fresh().follow(target, state)
    assert all(a.tobytes() == b.tobytes() for a, b in zip(again, expected))
    state[1][0] = 1e-4  # in place
    moved = used.limited_step(target, *state)
    expected = fresh().limited_step(target, *state)
    assert moved is not None and expected is not None
    assert all(a.tobytes() == b.tobytes() for a, b in zip(moved, expected))
    assert moved[0].tobytes() != first[0].tobytes()
