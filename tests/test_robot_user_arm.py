"""A user's arm MJCF plus a small mapping (joints, attachment site) holds a vessel: build, load, solve, save, reload."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from cosim.errors import InputError
from cosim.robots.ik import IKSettings
from cosim.robots.planar import tilt_about_pivot
from cosim.robots.scene import RobotScene
from cosim.robots.scene_builder import build_scene_spec, scene_mjcf
from cosim.robots.scene_config import ArmModel, ArmPlacement, ArmRole, MountSide, default_scene_config
from cosim.trajectory.driver_names import JointPrefix, driver_joint_names
from cosim.vessel import VesselSpec, seed_pouring_vessel

# A small 6-DOF arm in the style of a MuJoCo Menagerie model: its own joint names, a tool site whose z axis points
# out of the flange, `general` position servos (affine bias), no gravity compensation.
TEST_ARM_XML = """
<mujoco model="test_arm">
  <compiler angle="radian" autolimits="true"/>
  <default>
    <joint damping="2" armature="0.05" range="-3.14 3.14"/>
    <geom type="capsule" size="0.035" density="800"/>
    <general biastype="affine" gainprm="800" biasprm="0 -800 -80" ctrlrange="-3.14 3.14"/>
  </default>
  <worldbody>
    <body name="link0">
      <geom type="cylinder" size="0.08 0.05" pos="0 0 0.05"/>
      <body name="link1" pos="0 0 0.1">
        <joint name="j1" axis="0 0 1"/>
        <geom fromto="0 0 0 0 0 0.3"/>
        <body name="link2" pos="0 0 0.3">
          <joint name="j2" axis="0 1 0"/>
          <geom fromto="0 0 0 0.45 0 0"/>
          <body name="link3" pos="0.45 0 0">
            <joint name="j3" axis="0 1 0"/>
            <geom fromto="0 0 0 0.4 0 0"/>
            <body name="link4" pos="0.4 0 0">
              <joint name="j4" axis="0 1 0"/>
              <geom fromto="0 0 0 0.08 0 0" size="0.03"/>
              <body name="link5" pos="0.08 0 0">
                <joint name="j5" axis="0 0 1"/>
                <geom fromto="0 0 0 0.06 0 0" size="0.03"/>
                <body name="link6" pos="0.06 0 0">
                  <joint name="j6" axis="1 0 0"/>
                  <geom type="cylinder" size="0.03 0.02" pos="0.02 0 0" quat="0.7071068 0 0.7071068 0"/>
                  <site name="tool" pos="0.04 0 0" quat="0 0.7071068 0 0.7071068"/>
                </body>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <general name="a1" joint="j1"/> <general name="a2" joint="j2"/> <general name="a3" joint="j3"/>
    <general name="a4" joint="j4"/> <general name="a5" joint="j5"/> <general name="a6" joint="j6"/>
  </actuator>
</mujoco>
"""
JOINTS = ("j1", "j2", "j3", "j4", "j5", "j6")
# The same arm made redundant (7-DOF, like a Panda): a second wrist pitch on the axis of j4, so only j4 + j7 matters
# to the vessel and (j4 - j7) spans the task nullspace.
TEST_ARM7_XML = TEST_ARM_XML.replace(
    '<joint name="j4" axis="0 1 0"/>', '<joint name="j4" axis="0 1 0"/> <joint name="j7" axis="0 1 0"/>'
).replace('<general name="a6" joint="j6"/>', '<general name="a6" joint="j6"/> <general name="a7" joint="j7"/>')
# Reaching a vessel target: the acceptance tolerances of the project's IK (m, rad).
MAX_POSITION_ERROR_M = 1e-3
MAX_ROTATION_ERROR_RAD = math.radians(0.1)


def _config(tmp_path, xml: str, joints: tuple[str, ...], seed: tuple[float, ...]):
    path = tmp_path / "test_arm.xml"
    path.write_text(xml)
    default = default_scene_config()
    pour = ArmPlacement(
        role=ArmRole.POUR,
        arm=ArmModel(str(path), joints, "tool", (2.0,) * len(joints)),
        base_pos=(-0.55, 0.0, 0.75),
        base_yaw=0.0,
        vessel=seed_pouring_vessel(),
        vessel_home=(0.0, 0.0, 1.25),
        mount_side=MountSide.BACK,
        home_seed=seed,
    )
    cup = VesselSpec(name="catcher", shape="cylinder", inner_width=0.2, inner_height=0.14)
    catch = dataclasses.replace(default.catch, vessel=cup, vessel_home=(0.2, 0.0, 1.25 - 0.21 - 0.14))
    return dataclasses.replace(default, pour=pour, catch=catch)


@pytest.fixture
def config(tmp_path):
    return _config(tmp_path, TEST_ARM_XML, JOINTS, (0.0, -1.2, 2.0, -0.8, 0.0, 0.0))


def test_user_arm_holds_the_vessel_and_reaches_targets(config):
    scene = RobotScene.from_spec(build_scene_spec(config))
    arm = scene.arms[ArmRole.POUR]
    assert arm.joints == tuple(f"pour_arm/{j}" for j in JOINTS)
    np.testing.assert_allclose(arm.home_pos, config.pour.vessel_home, atol=1e-7)
    np.testing.assert_allclose(np.abs(arm.home_quat), [1, 0, 0, 0], atol=1e-7)
    assert scene.data.ncon == 0

    pose = tilt_about_pivot(arm.home_quat, arm.vessel.lip_local, math.radians(45.0))
    q = scene.solve_vessel_target(ArmRole.POUR, pose)
    target_pos, target_quat = scene.vessel_target(ArmRole.POUR, pose)
    scene.set_joint_positions(ArmRole.POUR, q)
    mujoco.mj_forward(scene.model, scene.data)
    state = scene.vessel_state(ArmRole.POUR)
    assert np.linalg.norm(state.pos - target_pos) <= MAX_POSITION_ERROR_M
    angle = 2 * math.acos(min(1.0, abs(float(np.dot(state.quat, target_quat)))))
    assert angle <= MAX_ROTATION_ERROR_RAD

    qd = np.full(6, 0.1)
    scene.set_joint_targets(ArmRole.POUR, q, qd)
    np.testing.assert_allclose(scene.data.ctrl[arm.ctrl_adr], q + (80.0 / 800.0) * qd)


def test_user_scene_survives_save_and_reload(config, tmp_path):
    path = tmp_path / "user_scene.xml"
    path.write_text(scene_mjcf(config))
    scene = RobotScene.load(path)
    assert scene.arms[ArmRole.POUR].joints[0] == "pour_arm/j1"
    assert scene.arms[ArmRole.CATCH].vessel.shape.value == "cylinder"
    np.testing.assert_allclose(scene.arms[ArmRole.POUR].max_joint_speed, 2.0)
    assert scene.data.ncon == 0


def test_user_arm_exports_its_drivers_joint_names(config, tmp_path):
    # without driver names the MJCF's are exported; with them, they are recorded in the scene file and exported
    assert RobotScene.from_config(config).arms[ArmRole.POUR].driver_joints == JOINTS
    driver = tuple(f"fr3_joint{k}" for k in range(1, 7))
    named = dataclasses.replace(config, pour=dataclasses.replace(config.pour, arm=dataclasses.replace(config.pour.arm, driver_joints=driver)))
    path = tmp_path / "user_scene.xml"
    path.write_text(scene_mjcf(named))
    scene = RobotScene.load(path)
    assert scene.arms[ArmRole.POUR].driver_joints == driver
    assert driver_joint_names(scene, JointPrefix(pour_arm="left_"))["pour_arm"] == tuple(f"left_{n}" for n in driver)


@pytest.mark.parametrize("driver", [("a",) * 6, ("a", "b"), ("a b", "c", "d", "e", "f", "g")])
def test_bad_driver_joint_names_are_refused(driver):
    with pytest.raises(InputError, match=r"^arm\.driver_joints: must name the arm's 6 joints once each, without spaces"):
        ArmModel("test_arm.xml", JOINTS, "tool", (2.0,) * 6, driver)


def test_bad_mapping_is_reported(config):
    wrong_site = dataclasses.replace(config.pour, arm=dataclasses.replace(config.pour.arm, flange_site="flange9"))
    with pytest.raises(InputError, match="pour_arm.arm.flange_site: no site 'flange9'"):
        build_scene_spec(dataclasses.replace(config, pour=wrong_site))
    wrong_joint = dataclasses.replace(
        config.pour, arm=dataclasses.replace(config.pour.arm, joints=("j1", "j2", "j3", "j4", "j5", "j7"))
    )
    with pytest.raises(InputError, match="pour_arm.arm.joints: no joint 'j7'"):
        build_scene_spec(dataclasses.replace(config, pour=wrong_joint))


def test_redundant_user_arm_is_pulled_toward_home_in_the_nullspace(tmp_path):
    config = _config(tmp_path, TEST_ARM7_XML, JOINTS + ("j7",), (0.0, -1.2, 2.0, -0.4, 0.0, 0.0, -0.4))
    scene = RobotScene.from_config(config)
    arm = scene.arms[ArmRole.POUR]
    j4, j7 = 3, 6
    seed = arm.home_q.copy()
    seed[j4] += 0.4  # a pure nullspace offset: the vessel does not move
    seed[j7] -= 0.4
    pose = tilt_about_pivot(arm.home_quat, arm.vessel.lip_local, math.radians(30.0))
    target_pos, target_quat = scene.vessel_target(ArmRole.POUR, pose)
    pulled = scene.ik(ArmRole.POUR, IKSettings(1e-6, 1e-6)).solve(target_pos, target_quat, seed)
    unpulled = scene.ik(ArmRole.POUR, IKSettings(1e-6, 1e-6, posture_gain=0.0)).solve(target_pos, target_quat, seed)
    assert pulled.converged and unpulled.converged
    assert pulled.position_error <= MAX_POSITION_ERROR_M and pulled.rotation_error <= MAX_ROTATION_ERROR_RAD
    split = lambda q: (q[j4] - q[j7]) - (arm.home_q[j4] - arm.home_q[j7])  # noqa: E731  nullspace coordinate
    assert abs(split(unpulled.q)) > 0.7  # without the pull the offset stays
    assert abs(split(pulled.q)) < 1e-2  # with it the solution returns to the home split
