"""The coupling-facing API of RobotScene: vessel state (pose, velocity, COM), wrench application, servo commands."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from cosim.robots.scene import RobotScene, shift_wrench
from cosim.robots.scene_config import ArmRole

# Finite-difference check of the vessel velocity over one 2 ms step: O(dt) truncation, m/s and rad/s.
VELOCITY_FD_TOL = 2e-3


@pytest.fixture
def scene() -> RobotScene:
    return RobotScene.load()


def test_vessel_velocity_matches_finite_difference(scene):
    arm = scene.arms[ArmRole.POUR]
    scene.set_joint_positions(ArmRole.POUR, arm.home_q, np.array([0.0, 0.3, -0.4, 0.5, 0.2, 0.1]))
    mujoco.mj_forward(scene.model, scene.data)
    before = scene.vessel_state(ArmRole.POUR)
    dt = scene.model.opt.timestep
    probe = mujoco.MjData(scene.model)
    probe.qpos[:] = scene.data.qpos
    mujoco.mj_integratePos(scene.model, probe.qpos, scene.data.qvel, dt)
    mujoco.mj_kinematics(scene.model, probe)
    lin_fd = (probe.xpos[arm.vessel_body] - before.pos) / dt
    quat_rel = np.empty(4)
    mujoco.mju_mulQuat(quat_rel, probe.xquat[arm.vessel_body], np.array([1, -1, -1, -1]) * before.quat)
    ang_fd = np.empty(3)
    mujoco.mju_quat2Vel(ang_fd, quat_rel, dt)
    np.testing.assert_allclose(before.lin_vel, lin_fd, atol=VELOCITY_FD_TOL)
    np.testing.assert_allclose(before.ang_vel, ang_fd, atol=VELOCITY_FD_TOL)
    np.testing.assert_allclose(before.velocity_at(before.pos), before.lin_vel)


def test_com_is_the_vessel_body_com(scene):
    state = scene.vessel_state(ArmRole.CATCH)
    vessel = scene.arms[ArmRole.CATCH].vessel
    np.testing.assert_allclose(state.com, state.pos + vessel.com_local, atol=1e-5)  # upright at home


def test_wrench_applied_at_com_equals_force_at_the_lip(scene):
    """A force at the lip, shifted to the COM, produces the same joint torques as the force applied at the lip."""
    arm = scene.arms[ArmRole.POUR]
    state = scene.vessel_state(ArmRole.POUR)
    force, lip = np.array([4.0, -1.0, -30.0]), scene.lip_position(ArmRole.POUR)
    torque = shift_wrench(force, np.zeros(3), lip, state.com)
    expected, actual = np.zeros(scene.model.nv), np.zeros(scene.model.nv)
    mujoco.mj_applyFT(scene.model, scene.data, force, np.zeros(3), lip, arm.vessel_body, expected)
    mujoco.mj_applyFT(scene.model, scene.data, force, torque, state.com, arm.vessel_body, actual)
    np.testing.assert_allclose(actual, expected, atol=1e-9)
    scene.apply_vessel_wrench(ArmRole.POUR, force, torque)
    np.testing.assert_array_equal(scene.data.xfrc_applied[arm.vessel_body], np.concatenate((force, torque)))


def test_servo_law_with_velocity_and_torque_feedforward(scene):
    """u = q_d + (kv qd_d + tau_ff)/kp gives actuator force kp (q_d - q) + kv (qd_d - qdot) + tau_ff."""
    arm = scene.arms[ArmRole.CATCH]
    q = scene.joint_positions(ArmRole.CATCH)
    q_d, qd_d, tau_ff = q + 0.01, np.full(6, 0.2), np.linspace(-3.0, 3.0, 6)
    scene.data.qvel[arm.dof_adr] = 0.05
    scene.set_joint_targets(ArmRole.CATCH, q_d, qd_d, tau_ff)
    mujoco.mj_forward(scene.model, scene.data)
    ids = [scene.model.actuator(name).id for name in arm.joints]
    expected = arm.kp * (q_d - q) + arm.kv * (qd_d - 0.05) + tau_ff
    np.testing.assert_allclose(scene.data.actuator_force[ids], expected, rtol=1e-9)


def test_wrench_feedforward_cancels_a_known_liquid_load(scene):
    """The full pourer's water weight (3.65 kg) pushed on the vessel: the servos alone sag, with feedforward they hold."""
    arm = scene.arms[ArmRole.POUR]
    weight = np.array([0.0, 0.0, -9.81 * 1000.0 * arm.vessel.capacity])

    def sag(feedforward: bool) -> float:
        scene.reset_home()
        scene.apply_vessel_wrench(ArmRole.POUR, weight, np.zeros(3))
        for _ in range(1000):  # 2 s
            tau = -scene.wrench_joint_torque(ArmRole.POUR, weight, np.zeros(3)) if feedforward else None
            scene.set_joint_targets(ArmRole.POUR, arm.home_q, None, tau)
            mujoco.mj_step(scene.model, scene.data)
        mujoco.mj_forward(scene.model, scene.data)
        return float(np.linalg.norm(scene.lip_position(ArmRole.POUR) - arm.home_pos - arm.vessel.lip_local))

    without, with_ff = sag(False), sag(True)
    assert without > 1e-3  # millimetres of sag from the servo stiffness alone
    assert with_ff < 1e-6


def test_vessel_pose_and_com_are_those_of_the_full_state(scene):
    """The every-step exchange reads pose and centre of mass without the velocity: the same values, copies."""
    scene.set_joint_positions(ArmRole.POUR, scene.arms[ArmRole.POUR].home_q + 0.1)
    mujoco.mj_forward(scene.model, scene.data)
    for role in (ArmRole.POUR, ArmRole.CATCH):
        state = scene.vessel_state(role)
        pos, quat = scene.vessel_pose(role)
        com = scene.vessel_com(role)
        np.testing.assert_array_equal(pos, state.pos)
        np.testing.assert_array_equal(quat, state.quat)
        np.testing.assert_array_equal(com, state.com)
        pos[:] = com[:] = 0.0
        assert np.any(scene.vessel_pose(role)[0] != 0.0) and np.any(scene.vessel_com(role) != 0.0)


def test_the_live_kinematics_give_the_private_jacobians_bit_for_bit(scene):
    """The step loop keeps the live frames current (mj_kinematics and mj_comPos after each mj_step): the wrench's
    joint torques read there are those the private data computes again, to the bit; stale frames are not."""
    force, torque = np.array([0.3, -0.2, -35.0]), np.array([0.01, 0.4, -0.02])
    for role in (ArmRole.POUR, ArmRole.CATCH):
        scene.set_joint_targets(role, scene.arms[role].home_q + 0.2)
    for _ in range(5):
        mujoco.mj_step(scene.model, scene.data)
    stale = scene.wrench_joint_torque(ArmRole.POUR, force, torque, kinematics_current=True)  # mj_step's frames: before its integration
    mujoco.mj_kinematics(scene.model, scene.data)
    mujoco.mj_comPos(scene.model, scene.data)
    for role in (ArmRole.POUR, ArmRole.CATCH):
        live = scene.wrench_joint_torque(role, force, torque, kinematics_current=True)
        private = scene.wrench_joint_torque(role, force, torque)
        assert live.tobytes() == private.tobytes()
    assert np.any(stale != scene.wrench_joint_torque(ArmRole.POUR, force, torque))
