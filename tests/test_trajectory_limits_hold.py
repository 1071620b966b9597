"""The generators hold the limits they are given by construction, and a path beyond a velocity limit stops at once.

A path that accelerates through a joint's velocity limit is clipped to it; the generator must not arrive at the limit
still accelerating (every continuation would then overshoot by a^2 / (2 j)). The scripted pour with a user limit 1 %
below what it needs either keeps the arm within it (a generator that clips and catches up) or stops at the first
target beyond it, naming arm, joint, time and limit (the arms' generators in scripted and coupled runs).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from cosim.robots.scene_config import ArmRole
from cosim.trajectory.checks import check_trajectory
from cosim.trajectory.generator import STREAM_DELAY_PERIODS, GeneratorSettings, TrajectoryGenerator, UntrackablePathError, _peak_speed, _spline_state
from cosim.trajectory.limits import ArmLimits, JointLimitOverride, JointLimits, arm_limits
from cosim.trajectory.recorder import TrajectoryRecorder
from cosim.trajectory.scripted import generate_scripted, pour_poses

CYCLES_PER_TARGET = 5  # 10 ms targets, 2 ms cycles
CONTROL_PERIOD = 0.01  # s: targets, and so the path's velocity, come this often
USER_LIMIT_FRACTION = 0.99  # the user's limit: 1 % below what the pour needs
JOINT = "pour_arm/wrist_1"  # the pour arm's fastest joint on this pour


def test_a_path_accelerating_through_the_velocity_limit_stays_within_it():
    vmax, amax, jmax, accel = 1.0, 5.0, 100.0, 2.0  # rad/s, rad/s^2, rad/s^3; the path: q = accel t^2 / 2
    limits = ArmLimits("arm", "test", (JointLimits("arm/j", vmax, amax, jmax, -10.0, 10.0),))
    generator = TrajectoryGenerator(limits, np.zeros(1))
    recorder = TrajectoryRecorder([generator])
    for k in range(200):
        generator.set_target(np.array([0.5 * accel * (0.01 * k) ** 2]))
        for _ in range(CYCLES_PER_TARGET):
            generator.step()
            recorder.record()
    trajectory = recorder.trajectory()
    check_trajectory(trajectory, [limits])
    assert np.abs(trajectory.velocities).max() <= vmax
    assert np.abs(trajectory.velocities).max() >= vmax * (1.0 - 1e-9)  # it does run at the limit
    assert generator.late_targets > 0  # and falls behind the path beyond it


def _replayed(scene, pour, limits: dict[ArmRole, ArmLimits], stop: bool):
    """The scripted pour's IK targets streamed into generators under ``limits`` (the scripted run's timing)."""
    settings = GeneratorSettings(stop_beyond_velocity_limit=stop)
    generators = [TrajectoryGenerator(limits[r], pour.targets[r][0], settings) for r in ArmRole]
    recorder = TrajectoryRecorder(generators)
    count = len(pour.targets[ArmRole.POUR])
    for k in range(count):
        for generator, role in zip(generators, ArmRole):
            generator.set_target(pour.targets[role][min(k + STREAM_DELAY_PERIODS, count - 1)])
        for _ in range(CYCLES_PER_TARGET):
            for generator in generators:
                generator.step()
            recorder.record()
    return recorder.trajectory()


def _user_limits(scene, pour):
    """(limits with JOINT's max_velocity 1 % below the pour's peak there, that limit, the first time it is exceeded)."""
    j = pour.trajectory.joint_names.index(JOINT)
    speed = np.abs(pour.trajectory.velocities[:, j])
    limit = USER_LIMIT_FRACTION * float(speed.max())
    override = {ArmRole.POUR: arm_limits(scene, ArmRole.POUR, {JOINT: JointLimitOverride(max_velocity=limit)})}
    first = float(pour.trajectory.time[np.argmax(speed > limit)])
    return {ArmRole.CATCH: arm_limits(scene, ArmRole.CATCH), **override}, limit, first


def test_a_user_limit_below_the_pours_need_is_respected_by_a_generator_that_catches_up(scene, scripted_pour):
    limits, limit, _ = _user_limits(scene, scripted_pour)
    trajectory = _replayed(scene, scripted_pour, limits, stop=False)
    check_trajectory(trajectory, list(limits.values()))
    j = trajectory.joint_names.index(JOINT)
    assert np.abs(trajectory.velocities[:, j]).max() <= limit


def test_a_user_limit_below_the_pours_need_stops_the_arm_generators_at_once(scene, scripted_pour, scripted_pour_spec):
    limits, limit, first = _user_limits(scene, scripted_pour)
    with pytest.raises(UntrackablePathError) as caught:
        _replayed(scene, scripted_pour, limits, stop=True)
    message = str(caught.value)
    assert "\n" not in message
    found = re.fullmatch(
        r"untrackable path: arm pour_arm, joint wrist_1, t=([0-9.]+) s: the target path moves at ([0-9.]+) rad/s, "
        r"above max_velocity ([0-9.]+) rad/s",
        message,
    )
    assert found, message
    assert float(found.group(3)) == pytest.approx(limit, rel=1e-5)
    assert float(found.group(2)) > limit
    assert abs(float(found.group(1)) - first) <= CONTROL_PERIOD  # at the target where the arm first needed more
    with pytest.raises(UntrackablePathError, match="arm pour_arm, joint wrist_1"):  # the scripted runs stop alike
        generate_scripted(scene, pour_poses(scene, scripted_pour_spec), limits=limits)


def test_the_stop_uses_the_spline_segments_exact_peak_speed():
    """The untrackable-velocity stop of a stream point checks the speed the arm will have on its spline segment: the
    largest of the segment's velocity, which a dense sampling of the segment reaches."""
    rng = np.random.default_rng(3)
    for _ in range(100):
        points = rng.normal(size=(4, 2))
        dense = np.max([np.abs(_spline_state(points, u, 0.01)[1]) for u in np.linspace(0.0, 1.0, 4001)], axis=0)
        peak = _peak_speed(points, 0.01)
        assert np.all(peak >= dense * (1.0 - 1e-12)) and np.all(peak <= dense * (1.0 + 1e-6))
