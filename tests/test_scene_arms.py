"""The scene file's ``[arms.pour]`` and ``[arms.catch]``: a user's arm MJCF (examples/arms/small_arm.xml, no actuators)
loads with the scene's servos and limits, reaches the pour's poses and exports its own joint names; the bundled UR10e
takes a base pose and a grasp; bad arms are refused by `cosim scene --check` and `cosim pour` alike, before any
simulation, with one line naming the field."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from cosim.cli.main import main
from cosim.errors import InputError
from cosim.pour_arms import ArmSettings, ArmsSettings
from cosim.pour_checks import check_pour, robot_scene
from cosim.pour_scene import PourScene, load_scene
from cosim.robots import assets
from cosim.robots.planar import tilt_about_pivot
from cosim.robots.scene_config import ArmRole, default_scene_config
from cosim.robots.ur10e import dh_forward_kinematics
from cosim.trajectory.driver_names import driver_joint_names
from tests.support.cli_refusal import refusal

EXAMPLES = assets.models_dir().parent / "examples"
EXAMPLE = EXAMPLES / "beaker_small_arm.toml"
SMALL_ARM = EXAMPLES / "arms" / "small_arm.xml"
JOINTS = tuple(f"joint_{k}" for k in range(1, 7))
# The UR5e's standard DH parameters (m, rad), as examples/arms/small_arm.xml cites them.
UR5E_DH = ((0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996), (0.0, -0.425, -0.3922, 0.0, 0.0, 0.0),
           (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0))


def _example_with(changes: str = "", section: str = "arms.pour") -> str:
    """The example scene (its arm file by its absolute path), with ``changes`` (TOML lines) replacing the keys they
    set in ``section``."""
    text = EXAMPLE.read_text().replace('"arms/small_arm.xml"', json.dumps(str(SMALL_ARM)))
    head, sep, rest = text.partition(f"[{section}]\n")
    body, nxt, tail = rest.partition("\n[")
    keys = {line.split("=", 1)[0].strip() for line in changes.splitlines() if "=" in line}
    kept = [line for line in body.splitlines() if line.split("=", 1)[0].strip() not in keys]
    return head + sep + "\n".join(kept + changes.splitlines()) + "\n" + nxt + tail


def test_the_small_arm_file_is_the_ur5e_kinematics():
    model = mujoco.MjModel.from_xml_path(str(SMALL_ARM))
    data = mujoco.MjData(model)
    assert model.nu == 0  # a plain file: the scene gives the servos
    site = model.site("tool0").id
    for q in np.random.default_rng(3).uniform(-3.0, 3.0, (5, 6)):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        expected = dh_forward_kinematics(q, *UR5E_DH)
        np.testing.assert_allclose(data.site_xpos[site], expected[:3, 3], atol=1e-12)
        np.testing.assert_allclose(data.site_xmat[site].reshape(3, 3), expected[:3, :3], atol=1e-12)


def test_a_user_arm_scene_loads_reaches_the_pour_and_exports_its_own_names():
    scene = load_scene(EXAMPLE)
    assert Path(scene.arms.pour.mjcf) == SMALL_ARM  # relative to the scene file
    plan = check_pour(scene)  # the home postures and the reach over the pour's poses, before any simulation
    robots = plan.robots
    for role in ArmRole:
        arm = robots.arms[role]
        settings = scene.arms.of(role)
        assert arm.joints == tuple(f"{role.value}/{j}" for j in JOINTS)
        np.testing.assert_array_equal(arm.kp, settings.servo_kp)
        np.testing.assert_array_equal(arm.kv, settings.servo_kv)
        np.testing.assert_array_equal(arm.max_joint_speed, settings.max_velocity)
        limits = plan.limits[role]
        assert limits.arm_model == "small_arm"
        np.testing.assert_array_equal(limits.array("rated_torque"), settings.rated_torque)
        np.testing.assert_array_equal(limits.array("max_position"), [6.283185, 6.283185, 3.141593, 6.283185, 6.283185, 6.283185])  # the file's
        np.testing.assert_allclose(arm.home_pos, robots.data.site_xpos[arm.frame_site])
        joint = robots.model.joint(arm.joints[0]).id
        assert robots.model.jnt_actgravcomp[joint] and robots.model.body_gravcomp[robots.model.jnt_bodyid[joint]] == 1.0
    names = driver_joint_names(robots, scene.trajectory.joint_prefix)
    assert names["pour_arm"] == tuple(f"pour_arm_{j}" for j in JOINTS)
    assert names["catch_arm"] == tuple(f"catch_arm_{j}" for j in JOINTS)

    pour = robots.arms[ArmRole.POUR]
    pose = tilt_about_pivot(pour.home_quat, pour.vessel.lip_local, math.radians(90.0))
    q = robots.solve_vessel_target(ArmRole.POUR, pose)
    data = robots.posed({ArmRole.POUR: q})
    target_pos, target_quat = robots.vessel_target(ArmRole.POUR, pose)
    assert np.linalg.norm(data.site_xpos[pour.frame_site] - target_pos) < 1e-4
    assert 2 * math.acos(min(1.0, abs(float(np.dot(data.xquat[pour.vessel_body], target_quat))))) < 1e-4


def test_a_short_user_arm_pour_writes_the_users_joint_names(tmp_path):
    scene = tmp_path / "short.toml"
    scene.write_text(_example_with("particles_across = 8", "fluid") + "\n[coupling]\nmax_duration = 0.05\n")
    assert main(["pour", str(scene), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    exported = json.loads((tmp_path / "run" / "trajectory.json").read_text())["arms"]
    assert exported["pour_arm"]["joint_names"] == [f"pour_arm_{j}" for j in JOINTS]
    assert exported["pour_arm"]["scene_joint_names"] == [f"pour_arm/{j}" for j in JOINTS]
    assert exported["catch_arm"]["arm_model"] == "small_arm"
    header = (tmp_path / "run" / "trajectory.csv").read_text().splitlines()[0]
    assert "pour_arm/joint_6.pos" in header and "shoulder_pan" not in header
    with open(tmp_path / "run" / "trajectory.mcap", "rb") as stream:
        topics = {channel.topic: list(message.joint_names)
                  for _, channel, _, message in make_reader(stream, decoder_factories=[DecoderFactory()]).iter_decoded_messages()}
    assert topics == {f"/{arm}/joint_trajectory": [f"{arm}_{j}" for j in JOINTS] for arm in ("pour_arm", "catch_arm")}


def test_the_default_arms_are_the_project_cell():
    assert PourScene().cell_config() is None  # the default pour still loads models/scene.xml
    cell = default_scene_config()
    assert ArmsSettings().apply(cell) == cell


def test_the_bundled_arm_takes_a_base_pose_and_a_grasp():
    shifted = ArmSettings(base_pos=(0.97, 0.17415, 0.75), grasp_pos=(-0.0955, 0.0, 0.10))
    robots = robot_scene(PourScene(arms=ArmsSettings(catch=shifted)))
    catch = robots.arms[ArmRole.CATCH]
    model, data = robots.model, robots.data
    base = model.body("catch_arm/base").id
    np.testing.assert_allclose(data.xpos[base], shifted.base_pos, atol=1e-12)
    site = model.site("catch_arm/flange").id
    in_flange = data.site_xmat[site].reshape(3, 3).T @ (data.xpos[catch.vessel_body] - data.site_xpos[site])
    np.testing.assert_allclose(in_flange, shifted.grasp_pos, atol=1e-9)
    np.testing.assert_allclose(catch.home_pos, default_scene_config().catch.vessel_home, atol=1e-7)  # home unchanged
    assert data.ncon == 0


def test_a_base_quaternion_and_a_grasp_orientation_pose_the_bundled_arms():
    flip = np.empty(4)  # the default catch grasp (R_y(90 deg)) turned half a turn about the flange axis
    mujoco.mju_mulQuat(flip, np.array([0.0, 0.0, 0.0, 1.0]), np.array([math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0]))
    scene = PourScene(arms=ArmsSettings(pour=ArmSettings(base_quat=(0.0, 0.0, 0.0, 1.0)),  # the cell's yaw of pi
                                        catch=ArmSettings(grasp_quat=tuple(flip))))
    robots, default = robot_scene(scene), robot_scene(PourScene())
    np.testing.assert_allclose(robots.arms[ArmRole.POUR].home_q, default.arms[ArmRole.POUR].home_q, atol=1e-5)
    catch = robots.arms[ArmRole.CATCH]
    site = robots.model.site("catch_arm/flange").id
    in_flange = np.empty(4)
    mujoco.mju_mat2Quat(in_flange, (robots.data.site_xmat[site].reshape(3, 3).T @ robots.data.xmat[catch.vessel_body].reshape(3, 3)).ravel())
    assert abs(float(np.dot(in_flange, flip))) == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(catch.home_pos, default_scene_config().catch.vessel_home, atol=1e-7)  # the vessel stays
    with pytest.raises(InputError, match=r"^arms\.catch\.base_pos: the vessels at home: .*\(catch_arm/wrist_1_link\) "
                                         r"touches table \(world\) \(arm-table"):
        check_pour(scene)  # the flipped wrist folds into the table


ARM = "arms.pour"
REFUSED = {
    "arm file missing": ('mjcf = "no_such_arm.xml"', rf"^{ARM}\.mjcf: file not found: .*no_such_arm\.xml$"),
    "joint not in the file": ('joints = ["joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_7"]',
                              rf"^{ARM}\.joints: no joint 'joint_7' in .*small_arm\.xml$"),
    "flange site not in the file": ('flange_site = "tool9"', rf"^{ARM}\.flange_site: no site 'tool9' in .*small_arm\.xml$"),
    "base out of reach": ("base_pos = [-1.5, -0.1333, 0.75]",
                          rf"^{ARM}\.base_pos: pour_arm home \(pourer\): unreachable, the closest pose found is [0-9.]+ mm"),
    "the pour's tilt out of reach": ("base_pos = [-0.8, -0.1333, 0.75]",
                                     rf"^{ARM}\.base_pos: the pourer tilted [0-9]+ deg about its (bottom middle|lip) "
                                     r"\(controller\.cfs\.max_tilt 100 deg\) is out of pour_arm's reach"),
    "no servos in the file or the scene": ("servo_kp = []\nservo_kv = []",
                                           rf"^{ARM}\.servo_kp: the arm file has no actuator on joint 'joint_1'; give each"),
    "user arm without speed limits": ("max_velocity = []", rf"^{ARM}\.max_velocity: a user's arm \({ARM}\.mjcf\) needs"),
    "too few torques": ("rated_torque = [150.0, 150.0, 150.0, 28.0, 28.0]",
                        rf"^{ARM}\.rated_torque: must be a list of 6 numbers"),
    "range wider than the file's": ("min_position = [-7.0, -6.0, -3.0, -6.0, -6.0, -6.0]\n"
                                    "max_position = [6.0, 6.0, 3.0, 6.0, 6.0, 6.0]",
                                    rf"^{ARM}\.min_position\[0\]: must be in \[-6.28318, 6.28318\] rad \(joint 'joint_1'"),
    "payload over the arm's rating": ("rated_payload = 0.3",
                                      r"^vessels\.pourer: 0\.[0-9] kg with its liquid and mount, more than the arm's rated "
                                      r"payload of 0\.3 kg"),
    "yaw and quaternion both": ("base_yaw = 3.14\nbase_quat = [0.0, 0.0, 0.0, 1.0]",
                                rf"^{ARM}\.base_quat: give base_yaw or base_quat, not both$"),
}


@pytest.mark.parametrize("case", REFUSED)
def test_scene_check_and_pour_refuse_a_bad_arm_with_the_same_line(case, tmp_path, capsys, monkeypatch):
    changes, expected = REFUSED[case]
    monkeypatch.chdir(tmp_path)  # a pour without --out would write under ./recordings
    (tmp_path / "scene.toml").write_text(_example_with(changes))
    checked = refusal(capsys, ["scene", "--check", "scene.toml"], "scene")
    poured = refusal(capsys, ["pour", "scene.toml", "--quiet"], "pour")
    assert checked == poured
    assert re.search(expected, checked.removeprefix("scene.toml: ")), checked
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.toml"]  # nothing written


def test_an_arm_whose_flange_site_is_on_an_unnamed_body_is_refused_by_name(tmp_path, capsys, monkeypatch):
    # the vessel's mount is built on that body by its name: MuJoCo's own error was a traceback
    monkeypatch.chdir(tmp_path)
    arm = SMALL_ARM.read_text().replace('<body name="link_6" ', "<body ")
    (tmp_path / "unnamed_flange.xml").write_text(arm)
    (tmp_path / "scene.toml").write_text(_example_with(f"mjcf = {json.dumps(str(tmp_path / 'unnamed_flange.xml'))}"))
    checked = refusal(capsys, ["scene", "--check", "scene.toml"], "scene")
    assert re.search(rf"^{ARM}\.flange_site: the body that holds site 'tool0' in .*unnamed_flange\.xml has no name", checked.removeprefix("scene.toml: ")), checked
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.toml", "unnamed_flange.xml"]


def test_an_ik_seed_alone_is_what_a_home_posture_in_collision_is_blamed_on(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scene.toml").write_text("[arms.pour]\nhome_seed = [-1.0, -1.0, -1.0, -1.0, -1.0, -1.0]\n")
    checked = refusal(capsys, ["scene", "--check", "scene.toml"], "scene")
    assert checked.removeprefix("scene.toml: ").startswith("arms.pour.home_seed: the vessels at home: "), checked


def test_the_bundled_arm_refuses_a_user_arms_mapping():
    with pytest.raises(InputError, match=r"^arms\.catch\.joints: the bundled UR10e brings its own; set arms\.catch\.mjcf"):
        ArmsSettings(catch=ArmSettings(joints=JOINTS))
