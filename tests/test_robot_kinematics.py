"""Forward kinematics of the UR10e MJCF against Universal Robots' published DH model; published masses."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from cosim.robots import assets
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.robots.ur10e import UR10E_JOINT_RANGE, UR10E_JOINTS, dh_forward_kinematics

# The MJCF is written from the DH table itself, so FK must agree to floating-point round-off (m, and unitless for
# rotation-matrix entries); 1e-9 leaves room for the 7-digit quaternions in the file (normalised on load).
FK_TOLERANCE = 1e-9
# Data sheet arm weight, kg (UR10e: 33.5 kg); the MJCF's masses are the UR table's links 1-6 plus the base remainder.
UR10E_WEIGHT_KG = 33.5
WEIGHT_TOLERANCE_KG = 0.01
N_CONFIGURATIONS = 50


def _random_configurations(n: int) -> np.ndarray:
    return np.random.default_rng(3).uniform(-2 * math.pi, 2 * math.pi, size=(n, 6))


def test_standalone_arm_fk_matches_dh_model():
    model = mujoco.MjModel.from_xml_path(str(assets.model_path(assets.UR10E_ARM)))
    data = mujoco.MjData(model)
    site = model.site("flange").id
    adr = [model.jnt_qposadr[model.joint(j).id] for j in UR10E_JOINTS]
    for q in _random_configurations(N_CONFIGURATIONS):
        data.qpos[adr] = q
        mujoco.mj_kinematics(model, data)
        expected = dh_forward_kinematics(q)
        np.testing.assert_allclose(data.site_xpos[site], expected[:3, 3], atol=FK_TOLERANCE)
        np.testing.assert_allclose(data.site_xmat[site].reshape(3, 3), expected[:3, :3], atol=FK_TOLERANCE)


@pytest.mark.parametrize("role", list(ArmRole))
def test_scene_arms_fk_matches_dh_model_in_their_base_frames(role):
    scene = RobotScene.load()
    m, d = scene.model, mujoco.MjData(scene.model)
    arm = scene.arms[role]
    base = m.body(f"{role.value}/base").id
    flange = m.site(f"{role.value}/flange").id
    for q in _random_configurations(10):
        d.qpos[arm.qpos_adr] = q
        mujoco.mj_kinematics(m, d)
        r_base = d.xmat[base].reshape(3, 3)
        rel_pos = r_base.T @ (d.site_xpos[flange] - d.xpos[base])
        rel_rot = r_base.T @ d.site_xmat[flange].reshape(3, 3)
        expected = dh_forward_kinematics(q)
        np.testing.assert_allclose(rel_pos, expected[:3, 3], atol=FK_TOLERANCE)
        np.testing.assert_allclose(rel_rot, expected[:3, :3], atol=FK_TOLERANCE)


def test_posed_places_the_named_arm_by_forward_kinematics_and_leaves_the_rest_at_home():
    scene = RobotScene.load()
    live = scene.data.qpos.copy()
    q = _random_configurations(1)[0]
    data = scene.posed({ArmRole.POUR: q})
    pour, catch = scene.arms[ArmRole.POUR], scene.arms[ArmRole.CATCH]
    np.testing.assert_array_equal(data.qpos[pour.qpos_adr], q)
    np.testing.assert_array_equal(data.qpos[catch.qpos_adr], catch.home_q)
    base = scene.model.body("pour_arm/base").id
    flange = scene.model.site("pour_arm/flange").id
    r_base = data.xmat[base].reshape(3, 3)
    expected = dh_forward_kinematics(q)
    np.testing.assert_allclose(r_base.T @ (data.site_xpos[flange] - data.xpos[base]), expected[:3, 3], atol=FK_TOLERANCE)
    np.testing.assert_array_equal(scene.data.qpos, live)


def test_arm_weight_matches_data_sheet():
    model = mujoco.MjModel.from_xml_path(str(assets.model_path(assets.UR10E_ARM)))
    assert abs(model.body_mass.sum() - UR10E_WEIGHT_KG) < WEIGHT_TOLERANCE_KG


def test_joint_ranges_match_data_sheet():
    model = mujoco.MjModel.from_xml_path(str(assets.model_path(assets.UR10E_ARM)))
    for name in UR10E_JOINTS:
        np.testing.assert_allclose(model.joint(name).range, UR10E_JOINT_RANGE, rtol=1e-9)
