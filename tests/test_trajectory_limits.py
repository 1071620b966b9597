"""Trajectory limits: data-sheet-like defaults from the scene, per-joint overrides, one-line errors for bad values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.robots.ur10e import UR10E_JOINT_RANGE, UR10E_MAX_JOINT_SPEED, UR10E_RATED_TORQUE
from cosim.trajectory.generator import GeneratorSettings
from cosim.trajectory.limits import (
    DEFAULT_MAX_ACCELERATION,
    DEFAULT_MAX_JERK,
    ArmLimits,
    JointLimitOverride,
    JointLimits,
    arm_limits,
    scene_limits,
)
from cosim.trajectory.recorder import TrajectoryRecorder

# models/scene.xml keeps joint speeds and ranges to 6 significant digits (2.0944 rad/s, 6.28319 rad).
SCENE_RTOL = 5e-6


@pytest.fixture(scope="module")
def scene() -> RobotScene:
    return RobotScene.load()


def test_defaults_come_from_the_data_sheet_and_the_model(scene):
    limits = scene_limits(scene)
    assert list(limits) == list(ArmRole)
    for role, arm in limits.items():
        assert arm.arm == role.value and arm.arm_model == "UR10e"
        assert arm.joint_names == scene.arms[role].joints
        np.testing.assert_array_equal(arm.array("max_velocity"), scene.arms[role].max_joint_speed)
        np.testing.assert_allclose(arm.array("max_velocity"), UR10E_MAX_JOINT_SPEED, rtol=SCENE_RTOL)
        np.testing.assert_array_equal(arm.array("max_acceleration"), DEFAULT_MAX_ACCELERATION)
        np.testing.assert_array_equal(arm.array("max_jerk"), DEFAULT_MAX_JERK)
        ranges = np.array([scene.model.joint(name).range for name in arm.joint_names])
        np.testing.assert_array_equal(arm.array("min_position"), ranges[:, 0])
        np.testing.assert_array_equal(arm.array("max_position"), ranges[:, 1])
        np.testing.assert_allclose(ranges, np.tile(UR10E_JOINT_RANGE, (len(ranges), 1)), rtol=SCENE_RTOL)
        np.testing.assert_array_equal(arm.array("rated_torque"), UR10E_RATED_TORQUE)  # the model's actuator force ranges


def test_overrides_replace_single_values_of_single_joints(scene):
    limits = arm_limits(
        scene,
        ArmRole.CATCH,
        {
            "elbow": JointLimitOverride(max_jerk=40.0, max_position=2.0),
            "catch_arm/wrist_3": JointLimitOverride(max_velocity=1.0, min_position=-1.0),
        },
    )
    defaults = arm_limits(scene, ArmRole.CATCH)
    changed = {"catch_arm/elbow": {"max_jerk": 40.0, "max_position": 2.0},
               "catch_arm/wrist_3": {"max_velocity": 1.0, "min_position": -1.0}}
    for new, old in zip(limits.joints, defaults.joints):
        for field in ("max_velocity", "max_acceleration", "max_jerk", "min_position", "max_position"):
            expected = changed.get(new.name, {}).get(field, getattr(old, field))
            assert getattr(new, field) == expected, (new.name, field)


def _joint(**kwargs) -> JointLimits:
    values = dict(name="pour_arm/elbow", max_velocity=3.0, max_acceleration=5.0, max_jerk=100.0,
                  min_position=-6.0, max_position=6.0)
    values.update(kwargs)
    return JointLimits(**values)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"max_velocity": -1.0}, "limits.pour_arm/elbow.max_velocity: must be in (0, 50] rad/s, got -1"),
        ({"max_velocity": math.nan}, "limits.pour_arm/elbow.max_velocity: must be a finite number, got nan"),
        ({"rated_torque": 0.0}, "limits.pour_arm/elbow.rated_torque: must be in (0, 100000] N m, got 0"),
        ({"max_acceleration": 0.0}, "limits.pour_arm/elbow.max_acceleration: must be in (0, 1000] rad/s^2, got 0"),
        ({"max_jerk": "fast"}, "limits.pour_arm/elbow.max_jerk: must be a number, got 'fast' (str)"),
        ({"max_jerk": 2e6}, "limits.pour_arm/elbow.max_jerk: must be in (0, 1e+06] rad/s^3, got 2e+06"),
        ({"min_position": 1.0, "max_position": 0.5}, "limits.pour_arm/elbow.max_position: must be in (1, 100] rad, got 0.5"),
        ({"min_position": -math.inf}, "limits.pour_arm/elbow.min_position: must be a finite number, got -inf"),
    ],
)
def test_bad_limit_values_name_the_field_and_range(kwargs, message):
    with pytest.raises(InputError) as info:
        _joint(**kwargs)
    assert str(info.value) == message
    assert "\n" not in str(info.value)


def test_bad_overrides_name_the_joint(scene):
    with pytest.raises(InputError, match=r"^limits.pour_arm: unknown joint 'knee'; the arm has shoulder_pan, "):
        arm_limits(scene, ArmRole.POUR, {"knee": JointLimitOverride(max_jerk=10.0)})
    with pytest.raises(InputError, match=r"^limits.pour_arm/elbow.max_jerk: must be in \(0, 1e\+06\] rad/s\^3, got -5$"):
        arm_limits(scene, ArmRole.POUR, {"elbow": JointLimitOverride(max_jerk=-5.0)})
    with pytest.raises(InputError, match=r"^limits.pour_arm/wrist_1.max_position: must be in \[-6.28319, 6.28319\] rad "
                                         r"\(the model's joint range\), got 7$"):
        arm_limits(scene, ArmRole.POUR, {"wrist_1": JointLimitOverride(max_position=7.0)})
    with pytest.raises(InputError, match=r"^limits override max_velocity: must be a number or None, got '2'$"):
        JointLimitOverride(max_velocity="2")


def test_arm_limits_reject_foreign_or_duplicate_joints():
    with pytest.raises(InputError, match=r"^limits.catch_arm.joints: names must be unique and start with 'catch_arm/'"):
        ArmLimits("catch_arm", "UR10e", (_joint(),))
    with pytest.raises(InputError, match=r"^limits.pour_arm.joints: names must be unique"):
        ArmLimits("pour_arm", "UR10e", (_joint(), _joint()))


def test_bad_generator_and_recorder_settings_name_the_field():
    with pytest.raises(InputError, match=r"^trajectory.cycle_time: must be in \(0, 0.1\] s, got 0$"):
        GeneratorSettings(cycle_time=0.0)
    with pytest.raises(InputError, match=r"^trajectory.control_period: must be in \[0.002, 1\] s, got 0.001$"):
        GeneratorSettings(control_period=0.001)
    with pytest.raises(InputError, match=r"^trajectory.sample_rate_hz: must be in \(0, 10000\] Hz, got -500$"):
        TrajectoryRecorder([], sample_rate_hz=-500.0)
