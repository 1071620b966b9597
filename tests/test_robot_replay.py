"""Replay of known trajectories through the position servos with the full-vessel payload; contact reporting."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.robots.payload import PayloadMode
from cosim.robots.planar import PlanarPose
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.robots.ur10e import UR10E_PAYLOAD_KG
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.pour_motion import Pivot, PourMotionSpec, plan_pour_trajectory
from cosim.trajectory.replay import Feedforward, replay

# Acceptance: RMS lip error of a smooth pour under the position servos with the full-vessel payload.
MAX_LIP_RMS_ERROR_M = 2e-3
# Holding home with gravity compensation of a known payload: no error beyond round-off (rad, m).
HOLD_TOLERANCE = 1e-9


@pytest.fixture(scope="module")
def scene() -> RobotScene:
    return RobotScene.load(payload=PayloadMode.FULL)


def _hold(scene: RobotScene, duration: float) -> JointTrajectory:
    names = tuple(n for arm in scene.arms.values() for n in arm.joints)
    q = np.concatenate([arm.home_q for arm in scene.arms.values()])
    zeros = np.zeros((2, q.size))
    return JointTrajectory(np.array([0.0, duration]), names, np.vstack((q, q)), zeros, zeros)


def test_payload_adds_the_liquid_mass(scene):
    empty = RobotScene.load(payload=PayloadMode.EMPTY)
    pourer = scene.arms[ArmRole.POUR].vessel
    added = scene.model.body_mass.sum() - empty.model.body_mass.sum()
    expected = 1000.0 * pourer.capacity * 2  # the pourer full, the catcher holding the same volume
    assert added == pytest.approx(expected, rel=1e-9)
    for role, arm in scene.arms.items():  # everything beyond the flange: mount, vessel, liquid
        flange = arm.flange_body
        carried = sum(scene.model.body_mass[b] for b in range(scene.model.nbody) if _below(scene.model, b, flange))
        assert 0.0 < carried < UR10E_PAYLOAD_KG, f"{role.value} carries {carried:.2f} kg"


def _below(model, body: int, ancestor: int) -> bool:
    while body > 0:
        body = int(model.body_parentid[body])
        if body == ancestor:
            return True
    return False


def test_holding_home_has_no_tracking_error(scene):
    report = replay(scene, _hold(scene, 1.0))
    assert np.max(report.joint_max_error) < HOLD_TOLERANCE
    assert report.max_error_m < HOLD_TOLERANCE
    assert report.first_contact is None and report.contact_steps == 0


def test_smooth_pour_is_tracked_within_acceptance(scene):
    spec = PourMotionSpec(duration=6.0, max_tilt=math.radians(90.0), pivot=Pivot.LIP, catcher_dx=0.1)
    trajectory = plan_pour_trajectory(scene, spec)
    gravity = replay(scene, trajectory, Feedforward.GRAVITY)
    dynamics = replay(scene, trajectory, Feedforward.DYNAMICS)
    assert gravity.first_contact is None and dynamics.first_contact is None
    assert gravity.lip_rms_error["pourer"] <= MAX_LIP_RMS_ERROR_M
    assert 0.0 < dynamics.lip_rms_error["pourer"] < gravity.lip_rms_error["pourer"]
    assert np.all(gravity.peak_torque_fraction < 1.0)  # no joint saturates
    payload = gravity.to_json()
    assert payload["max_error_m"] == pytest.approx(gravity.lip_max_error["pourer"])
    assert set(payload["joint_max_error_rad"]) == set(trajectory.joint_names)


def test_replay_reports_a_collision(scene):
    """Lifting the catcher 0.3 m drives its rim into the pourer: the replay must report the contact."""
    arm = scene.arms[ArmRole.CATCH]
    q_end = scene.solve_vessel_target(ArmRole.CATCH, PlanarPose(dz=0.3), arm.home_q)
    t = np.linspace(0.0, 2.0, 41)
    s = t / 2.0
    blend = s**3 * (10 - 15 * s + 6 * s * s)
    q = arm.home_q + np.outer(blend, q_end - arm.home_q)
    qd = np.gradient(q, t, axis=0)
    trajectory = JointTrajectory(t, arm.joints, q, qd, np.gradient(qd, t, axis=0))
    report = replay(scene, trajectory)
    assert report.first_contact is not None
    assert {report.first_contact.body1, report.first_contact.body2} & {"pourer", "catcher"}


def test_partial_arm_is_rejected(scene):
    arm = scene.arms[ArmRole.POUR]
    zeros = np.zeros((2, 2))
    trajectory = JointTrajectory(np.array([0.0, 1.0]), arm.joints[:2], zeros, zeros, zeros)
    with pytest.raises(InputError, match="pour_arm is missing joint"):
        replay(scene, trajectory)
