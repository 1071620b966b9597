"""The task-space pose filter: jerk-limited, and calm under a target that chatters (CFS increments of either sign)."""

import numpy as np

from cosim.coupling.pose_filter import PoseFilter, PoseFilterLimits
from cosim.robots.planar import PlanarPose

PERIOD = 0.01  # s, the control period
# A target chattering by +-CHATTER around a constant must leave the filtered tilt within a few chatter amplitudes of
# it (a filter that reads the chatter as path velocity ran into a +-0.1 rad limit cycle in the coupled pour).
CHATTER = 0.002  # rad
CALM_BAND = 3 * CHATTER
# A ramp at the CFS rate limit is followed with at most the lag of a jerk-limited stop from that rate
# (v^2 / 2a + v a / 2j) plus the travel of the re-planning: every period the filter plans a new stop from a state
# already part-way into the last one's jerk phase (measured: 0.9 periods of travel at 40 rad/s^3, 2.5 at the
# default 20 rad/s^3), bounded here by three periods.
RAMP_RATE = 0.35  # rad/s
REPLANNING_PERIODS = 3


def _filter() -> PoseFilter:
    return PoseFilter("pourer_pose", ("dx", "dz", "theta"), PoseFilterLimits(), PERIOD)


def test_chattering_target_does_not_start_a_limit_cycle() -> None:
    f = _filter()
    tilts = []
    for k in range(600):
        target = 1.2 if k < 100 else 1.2 + 0.35 + CHATTER * (-1) ** k  # a move, then chatter about 1.55 rad
        tilts.append(f(PlanarPose(0.0, 0.0, target)).theta)
    settled = np.array(tilts[300:])
    assert np.max(np.abs(settled - 1.55)) <= CALM_BAND


def test_a_ramp_is_followed_with_a_bounded_lag() -> None:
    f = _filter()
    limits = PoseFilterLimits()
    a, j = limits.tilt_acceleration, limits.tilt_jerk
    lag_bound = RAMP_RATE**2 / (2 * a) + RAMP_RATE * a / (2 * j) + REPLANNING_PERIODS * RAMP_RATE * PERIOD
    lags = []
    for k in range(300):
        target = RAMP_RATE * k * PERIOD
        lags.append(target - f(PlanarPose(0.0, 0.0, target)).theta)
    assert max(lags[100:]) <= lag_bound
    assert min(lags) >= -1e-9  # each target is one to stop at: never ahead of the ramp


def test_pass_through_returns_the_command_and_filtering_resumes_from_its_motion() -> None:
    """A feedback command passes unchanged; afterwards the filter starts from the passed path's position and rate,
    so the first filtered pose continues it instead of jumping back to where the filter was."""
    f = _filter()
    rate = 0.2  # rad/s, a slow ramp, as the smoothed PID command moves
    passed = [f(PlanarPose(0.0, 0.0, rate * k * PERIOD), pass_through=True).theta for k in range(50)]
    assert passed == [rate * k * PERIOD for k in range(50)]
    resumed = f(PlanarPose(0.0, 0.0, rate * 50 * PERIOD)).theta
    # continues from 49 * rate * PERIOD at about the ramp's rate: within a tenth of one period's travel
    assert abs(resumed - rate * 50 * PERIOD) <= 0.1 * rate * PERIOD


def test_pass_through_waits_until_the_filter_has_caught_up() -> None:
    """A pass-through command far from the filtered pose (the filter still lagging a large move) is filtered, not
    jumped to, until the filtered pose reaches it."""
    f = _filter()
    first = f(PlanarPose(0.0, 0.0, 0.5), pass_through=True).theta
    assert 0.0 < first < 0.01  # one jerk-limited period of motion from rest, not the 0.5 rad step
    tilts = [f(PlanarPose(0.0, 0.0, 0.5), pass_through=True).theta for _ in range(300)]
    assert tilts[-1] == 0.5  # caught up, then passed through exactly
    assert max(abs(b - a) for a, b in zip(tilts, tilts[1:])) <= PoseFilterLimits().tilt_velocity * PERIOD + 1e-12
