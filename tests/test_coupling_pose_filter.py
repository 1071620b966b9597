"""The task-space pose filter: jerk-limited, and calm under a target that chatters (CFS increments of either sign);
the linear smoothing after it, which calms the filter's chase of a small slosh-induction excitation."""

import numpy as np
import pytest

from controllers.slosh_induction import excitation_tilt
from cosim.coupling.pose_filter import (
    HANDOVER_TIME, PASS_THROUGH_JOIN, SMOOTHING_BANDWIDTH, SMOOTHING_DELAY, SMOOTHING_STAGES, PoseFilter, PoseFilterLimits,
    PoseSmoother,
)
from cosim.robots.planar import PlanarPose
from cosim.trajectory.smoothness import acceleration_rms_above, jerk_sign_changes

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


# The linear smoothing after the jerk-limited filter: a ramp comes out delayed by its stated delay (once the start has
# died away), a bang-bang jerk (the filter's ripple) is rolled off, and the sampled rates stay within the input's.


def _smoothed(tilts: list[float]) -> np.ndarray:
    smoother = PoseSmoother(("theta",), PERIOD)
    return np.array([smoother(PlanarPose(0.0, 0.0, tilt)).theta for tilt in tilts])


def test_a_ramp_is_smoothed_with_its_stated_delay() -> None:
    ramp = [RAMP_RATE * k * PERIOD for k in range(300)]
    out = _smoothed(ramp)
    # discrete stages y += a (x - y): each delays a ramp by (1 - a) / a periods, the continuous 1 / bandwidth to
    # within (bandwidth x period)^2 / 12 of itself
    lag = (np.array(ramp) - out)[-1] / RAMP_RATE
    assert lag == pytest.approx(SMOOTHING_DELAY, rel=1e-9)
    # each stage y += a (x - y) lags a ramp by (1 - a) / a periods
    a = 1.0 - np.exp(-SMOOTHING_BANDWIDTH * PERIOD)
    assert SMOOTHING_DELAY == pytest.approx(SMOOTHING_STAGES * (1.0 - a) / a * PERIOD, rel=1e-12)


def test_a_bang_bang_jerk_is_rolled_off_and_the_rates_stay_within_the_input() -> None:
    # a tilt whose jerk flips between +-20 rad/s^3 every period: the jerk-limited filter's ripple at the control rate
    jerk = 20.0 * np.where(np.arange(400) % 2 == 0, 1.0, -1.0)
    acceleration = np.cumsum(jerk) * PERIOD
    tilt = np.cumsum(np.cumsum(acceleration) * PERIOD) * PERIOD
    out = _smoothed(tilt.tolist())
    for order in (1, 2, 3):
        assert np.abs(np.diff(out, order)).max() <= np.abs(np.diff(tilt, order)).max() + 1e-15
    ripple_in = np.abs(np.diff(tilt, 3)[200:]).max()
    ripple_out = np.abs(np.diff(out, 3)[200:]).max()
    # three stages at 60 rad/s pass a 50 Hz alternation as ((1 - (1 - a)) / (1 + (1 - a)))^3, a = 1 - exp(-0.6)
    a = 1.0 - np.exp(-SMOOTHING_BANDWIDTH * PERIOD)
    assert ripple_out == pytest.approx(ripple_in * (a / (2.0 - a)) ** 3, rel=0.01)


def test_a_passed_through_command_is_not_delayed_and_the_hand_overs_have_no_step() -> None:
    smoother = PoseSmoother(("theta",), PERIOD)
    rate = 0.2  # rad/s: a ramp filtered for 1 s, passed through for 1 s, filtered again
    out = np.array([smoother(PlanarPose(0.0, 0.0, rate * k * PERIOD), passing=100 <= k < 200).theta for k in range(300)])
    command = rate * np.arange(300) * PERIOD
    blended = 100 + round(HANDOVER_TIME / PERIOD)
    assert np.all(out[blended:200] == command[blended:200])  # passed through, once the hand-over's blend is over
    assert out[299] == pytest.approx(command[299] - rate * SMOOTHING_DELAY, abs=1e-9)  # filtering again: delayed
    # each hand-over blends out the smoothing's lag d = rate x delay: its acceleration peaks at 5.77 d / time^2
    # (the quintic blend), the ramp's own is zero; a step in the path or its rate would show as far more
    peak = 5.78 * rate * SMOOTHING_DELAY / HANDOVER_TIME**2
    assert np.abs(np.diff(out[50:], 2)).max() / PERIOD**2 <= peak


def test_a_command_joined_off_the_path_is_blended_in_without_a_step() -> None:
    # at rest, then passed a command PASS_THROUGH_JOIN away (the most the pose filter joins): no step in the output,
    # its acceleration at most the blend's 5.77 d / time^2
    smoother = PoseSmoother(("theta",), PERIOD)
    out = np.array([smoother(PlanarPose(0.0, 0.0, PASS_THROUGH_JOIN if k >= 50 else 0.0), passing=k >= 50).theta for k in range(100)])
    assert np.abs(np.diff(out, 2)).max() / PERIOD**2 <= 5.78 * PASS_THROUGH_JOIN / HANDOVER_TIME**2
    assert out[-1] == PASS_THROUGH_JOIN


def test_a_change_of_the_undelayed_source_is_blended_like_a_hand_over() -> None:
    # undelayed throughout, the source switches from a path at rest to a command PASS_THROUGH_JOIN away
    smoother = PoseSmoother(("theta",), PERIOD)
    out = np.array([
        smoother(PlanarPose(0.0, 0.0, PASS_THROUGH_JOIN if k >= 50 else 0.0), passing=True, source="command" if k >= 50 else "limited").theta
        for k in range(100)
    ])
    assert np.abs(np.diff(out, 2)).max() / PERIOD**2 <= 5.78 * PASS_THROUGH_JOIN / HANDOVER_TIME**2
    assert out[-1] == PASS_THROUGH_JOIN


def test_a_small_excitation_chased_by_the_filter_is_calmed_by_the_smoothing() -> None:
    """The slosh induction's excitation phi sin(alpha t), held at phi after a quarter period, as the pour's filter
    sees it: at a high fill's small phi the jerk-limited filter catches up and re-plans a stop at every target,
    bang-bang in jerk; the smoothing stages the coupling applies to it keep its rates within the filter's and take
    out most of that ripple: at most half the jerk sign changes and a third of the acceleration content above 10 Hz."""
    phi, alpha = 0.056, np.pi  # rad, rad/s: a 97 % fill's excitation, a quarter period of 0.5 s
    f, smoother = _filter(), PoseSmoother(("dx", "dz", "theta"), PERIOD)
    limited, smoothed = [], []
    for k in range(150):
        pose = f(PlanarPose(0.0, 0.0, excitation_tilt(k * PERIOD, phi, alpha)))
        limited.append(pose.theta)
        smoothed.append(smoother(pose).theta)

    def figures(tilt: list[float]) -> tuple[int, float]:
        acceleration = np.diff(tilt, 2) / PERIOD**2
        changes = jerk_sign_changes((np.diff(acceleration) / PERIOD)[:, None])[0]
        return int(changes), float(acceleration_rms_above(acceleration[:, None], 1.0 / PERIOD)[0])

    for order in (1, 2, 3):
        assert np.abs(np.diff(smoothed, order)).max() <= np.abs(np.diff(limited, order)).max() + 1e-15
    (chased, content), (calmed, rest) = figures(limited), figures(smoothed)
    assert chased >= 8, "the filter alone chases the small excitation bang-bang"
    assert calmed <= chased // 2
    assert rest <= content / 3.0
