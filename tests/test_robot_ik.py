"""Inverse kinematics: accuracy over pour-workspace targets, planar target helpers, failure message, no side effects."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from cosim.errors import InputError
from cosim.robots.ik import rotation_error
from cosim.frames import quat_wxyz_to_matrix, rotation_y
from cosim.robots.planar import PlanarPose, planar_to_world, tilt_about_pivot
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole

# Acceptance: vessel targets reached within 1 mm and 0.1 deg.
MAX_POSITION_ERROR_M = 1e-3
MAX_ROTATION_ERROR_RAD = math.radians(0.1)


@pytest.fixture(scope="module")
def scene() -> RobotScene:
    return RobotScene.load()


def _fk_errors(scene: RobotScene, role: ArmRole, q: np.ndarray, pose: PlanarPose) -> tuple[float, float]:
    """Independent check: pose the solution on a fresh MjData and measure the vessel frame against the target."""
    arm = scene.arms[role]
    data = mujoco.MjData(scene.model)
    data.qpos[:] = scene.data.qpos
    data.qpos[arm.qpos_adr] = q
    mujoco.mj_kinematics(scene.model, data)
    pos, quat = scene.vessel_target(role, pose)
    e_pos = float(np.linalg.norm(data.site_xpos[arm.frame_site] - pos))
    e_rot = float(np.linalg.norm(rotation_error(quat_wxyz_to_matrix(quat), data.site_xmat[arm.frame_site].reshape(3, 3))))
    return e_pos, e_rot


@pytest.mark.parametrize("pivot", ["bottom", "lip"])
@pytest.mark.parametrize("tilt_deg", [0.0, 35.0, 80.0, 120.0])
def test_pourer_tilt_targets_are_reached(scene, pivot, tilt_deg):
    arm = scene.arms[ArmRole.POUR]
    point = np.zeros(3) if pivot == "bottom" else arm.vessel.lip_local
    pose = tilt_about_pivot(arm.home_quat, point, math.radians(tilt_deg))
    q = scene.solve_vessel_target(ArmRole.POUR, pose, arm.home_q)
    e_pos, e_rot = _fk_errors(scene, ArmRole.POUR, q, pose)
    assert e_pos <= MAX_POSITION_ERROR_M and e_rot <= MAX_ROTATION_ERROR_RAD


@pytest.mark.parametrize("dx", [-0.15, -0.05, 0.1, 0.15])
def test_catcher_translation_targets_are_reached(scene, dx):
    pose = PlanarPose(dx=dx)
    q = scene.solve_vessel_target(ArmRole.CATCH, pose, scene.arms[ArmRole.CATCH].home_q)
    e_pos, e_rot = _fk_errors(scene, ArmRole.CATCH, q, pose)
    assert e_pos <= MAX_POSITION_ERROR_M and e_rot <= MAX_ROTATION_ERROR_RAD


def test_tilt_about_lip_keeps_the_lip_in_place(scene):
    arm = scene.arms[ArmRole.POUR]
    pose = tilt_about_pivot(arm.home_quat, arm.vessel.lip_local, math.radians(90.0))
    q = scene.solve_vessel_target(ArmRole.POUR, pose, arm.home_q)
    data = mujoco.MjData(scene.model)
    data.qpos[:] = scene.data.qpos
    data.qpos[arm.qpos_adr] = q
    mujoco.mj_kinematics(scene.model, data)
    np.testing.assert_allclose(data.site_xpos[arm.lip_site], scene.lip_position(ArmRole.POUR), atol=MAX_POSITION_ERROR_M)


def test_planar_pose_convention():
    """R_y(theta) lowers the +x lip for positive theta; tilts compose about the current pivot."""
    home_pos, home_quat = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0, 0.0])
    lip = np.array([0.1, 0.0, 0.2])
    pos, quat = planar_to_world(home_pos, home_quat, PlanarPose(theta=math.radians(30.0)))
    assert (pos + quat_wxyz_to_matrix(quat) @ lip)[2] < (home_pos + lip)[2]
    np.testing.assert_allclose(rotation_y(0.3) @ rotation_y(0.4), rotation_y(0.7), atol=1e-15)
    first = tilt_about_pivot(home_quat, lip, 0.4)
    second = tilt_about_pivot(home_quat, lip, 0.5, current=first)
    both = tilt_about_pivot(home_quat, lip, 0.9)
    assert (second.dx, second.dz, second.theta) == pytest.approx((both.dx, both.dz, both.theta), abs=1e-12)


def test_solving_does_not_touch_the_live_simulation(scene):
    qpos, ctrl = scene.data.qpos.copy(), scene.data.ctrl.copy()
    scene.solve_vessel_target(ArmRole.POUR, PlanarPose(theta=math.radians(60.0)))
    np.testing.assert_array_equal(scene.data.qpos, qpos)
    np.testing.assert_array_equal(scene.data.ctrl, ctrl)


def test_unreachable_target_names_target_and_distance(scene):
    pose = PlanarPose(dx=0.0, dz=2.5, theta=0.0)  # 2.5 m above home: beyond the 1.3 m reach
    with pytest.raises(InputError) as info:
        scene.solve_vessel_target(ArmRole.POUR, pose)
    message = str(info.value)
    assert "\n" not in message
    assert "pourer target (dx=0.000 m, dz=2.500 m, tilt=0.0 deg)" in message and "unreachable" in message
    distance_mm = float(message.split("closest pose found is ")[1].split(" mm")[0])
    assert 500.0 < distance_mm < 2500.0  # the remaining distance is reported, in mm
