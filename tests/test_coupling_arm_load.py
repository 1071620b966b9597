"""Coupling as a real arm (coarse, short pours): what each compensation lets the arms feel, the vessel deviation the
liquid causes, the drives' torques, and the inverse dynamics of the exported trajectory."""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np
import pytest

from cosim.coupling.settings import Compensation, Coupling
from cosim.pour_run import prepare
from cosim.pour_scene import load_scene
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.checks import UnsafeTrajectoryError, check_torques
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.limits import JointLimitOverride, arm_limits, scene_limits
from cosim.trajectory.torques import required_torques

COARSE = """
name = "arm-load"
[fluid]
particles_across = 10
[coupling]
max_duration = 0.6
"""
# s: the ideally compensated and the one-way coarse pour command the same trajectory, bit for bit, at least this long
# (the liquids differ by round-off, which the controller's measurement turns into different commands from 0.48 s on).
SAME_COMMANDS_S = 0.4
# m: a vessel deviation that is round-off, not the liquid (the twin and the live arm take the same steps).
ROUND_OFF_M = 1e-12
# The full pourer's 2.9 kg of liquid on servos of 2000-10000 N m/rad: its slosh and inertia, uncompensated by a
# static payload setting, move the vessel by a tenth of a millimetre (measured 0.147 mm on the coarse pour) and change
# the drives' torques by newton-metres; thresholds an order below.
PHYSICAL_DEVIATION_M = 1e-5
PHYSICAL_TORQUE_NM = 1.0


def _run(tmp_path, coupling: Coupling, compensation: Compensation):
    path = tmp_path / "scene.toml"
    path.write_text(COARSE)
    scene = load_scene(path)
    scene = replace(scene, coupling=replace(scene.coupling, coupling=coupling, compensation=compensation))
    pour = prepare(scene)
    summary = pour.run()
    trajectory = pour.recorder.trajectory()
    torques = required_torques(pour.scene, trajectory, pour.sample_wrenches(trajectory.time))
    return pour, summary, trajectory, torques


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("arm-load")
    return {
        "one_way": _run(tmp, Coupling.ONE_WAY, Compensation.STATIC_PAYLOAD),
        "ideal": _run(tmp, Coupling.TWO_WAY, Compensation.IDEAL_FORCE_TORQUE),
        "static": _run(tmp, Coupling.TWO_WAY, Compensation.STATIC_PAYLOAD),
    }


def _deviation(summary, role: ArmRole) -> float:
    return summary["arm_load"][role.value]["liquid_deviation_mm"] * 1e-3


def test_one_way_arms_do_not_feel_the_liquid(runs):
    _, summary, _, _ = runs["one_way"]
    for role in ArmRole:
        assert summary["arm_load"][role.value]["compensation"] == "one_way"
        assert _deviation(summary, role) == 0.0 and summary["arm_load"][role.value]["liquid_deviation_deg"] == 0.0


def test_ideal_force_torque_compensation_moves_the_arms_as_one_way(runs):
    _, _, traj_one, torques_one = runs["one_way"]
    _, ideal, traj_ideal, torques_ideal = runs["ideal"]
    for role in ArmRole:
        assert _deviation(ideal, role) <= ROUND_OFF_M
    same = np.all(traj_ideal.positions == traj_one.positions, axis=1) & np.all(traj_ideal.accelerations == traj_one.accelerations, axis=1)
    assert same[traj_one.time <= SAME_COMMANDS_S].all()
    # the same commands under the same (up to round-off) liquid: the same torques a real arm needs
    np.testing.assert_allclose(torques_ideal[same], torques_one[same], rtol=1e-9, atol=1e-9)


def test_a_static_payload_setting_lets_the_arm_feel_the_rest_of_the_liquid(runs):
    _, one_way, _, _ = runs["one_way"]
    pour, static, _, _ = runs["static"]
    assert _deviation(static, ArmRole.POUR) >= PHYSICAL_DEVIATION_M
    assert _deviation(static, ArmRole.CATCH) == 0.0  # nothing caught yet: the catcher's arm feels nothing
    servo = [np.array(list(r["arm_load"][ArmRole.POUR.value]["peak_servo_torque"].values())) for r in (one_way, static)]
    assert np.abs(servo[1] - servo[0]).max() >= PHYSICAL_TORQUE_NM  # the drives carry the liquid two-way only
    for role in ArmRole:
        record = static["arm_load"][role.value]
        assert list(record["peak_servo_torque"]) == list(pour.scene.arms[role].joints)


def test_required_torques_at_rest_are_the_servo_torques_that_hold_the_load():
    """Inverse dynamics against forward dynamics: the pour arm held at home under a liquid-like wrench (weight and a
    torque), fed forward exactly, settles where the servos' torques are the required ones."""
    scene = RobotScene.load()
    arm = scene.arms[ArmRole.POUR]
    wrench = np.array([1.5, 0.0, -30.0, 0.0, 0.8, 0.0])  # N, N m at the vessel's centre of mass
    scene.apply_vessel_wrench(ArmRole.POUR, wrench[:3], wrench[3:])
    for _ in range(1000):
        tau = -scene.wrench_joint_torque(ArmRole.POUR, wrench[:3], wrench[3:])
        for role in ArmRole:
            scene.set_joint_targets(role, scene.arms[role].home_q, None, tau if role is ArmRole.POUR else None)
        mujoco.mj_step(scene.model, scene.data)
    mujoco.mj_forward(scene.model, scene.data)
    names = tuple(n for role in ArmRole for n in scene.arms[role].joints)
    q = np.concatenate([scene.arms[role].home_q for role in ArmRole])
    still = JointTrajectory(np.array([0.0, 0.002]), names, np.tile(q, (2, 1)), np.zeros((2, 12)), np.zeros((2, 12)))
    torques = required_torques(scene, still, {ArmRole.POUR: np.tile(wrench, (2, 1)), ArmRole.CATCH: np.zeros((2, 6))})
    np.testing.assert_allclose(torques[0, :6], scene.data.qfrc_actuator[arm.dof_adr], rtol=1e-6, atol=1e-6)


def test_a_rated_torque_below_the_need_refuses_the_trajectory_naming_the_joint(runs):
    pour, _, trajectory, torques = runs["static"]
    j = trajectory.joint_names.index("pour_arm/elbow")
    need = float(np.abs(torques[:, j]).max())
    check_torques(trajectory, torques, pour.recorder.limits)  # within the UR10e's ratings
    low = {ArmRole.POUR: {"elbow": JointLimitOverride(rated_torque=0.99 * need)}}
    limits = list(scene_limits(pour.scene, low).values())
    with pytest.raises(UnsafeTrajectoryError, match=r"^unsafe trajectory: arm pour_arm, joint elbow, t=[0-9.]+ s: \|required torque\| [0-9.]+ N m above rated_torque [0-9.]+ N m$"):
        check_torques(trajectory, torques, limits)
    assert arm_limits(pour.scene, ArmRole.POUR).joints[2].rated_torque == 150.0


def test_vectorised_rotation_angles_are_the_exact_ones_to_round_off():
    from cosim.coupling.arm_load import rotation_angle, rotation_angles

    rng = np.random.default_rng(0)
    a = rng.normal(size=(200, 4))
    a /= np.linalg.norm(a, axis=1)[:, None]
    b = a + rng.normal(size=(200, 4)) * 10.0 ** rng.uniform(-12, 0, size=(200, 1))  # from 1e-12 rad to large angles
    b /= np.linalg.norm(b, axis=1)[:, None]
    exact = np.array([rotation_angle(x, y) for x, y in zip(a, b)])
    assert np.abs(rotation_angles(a, b) - exact).max() < 1e-14


def test_largest_is_the_exact_maximum_where_the_screen_rounds_differently():
    from cosim.coupling.arm_load import largest

    exact = np.array([1e-4, 3e-4, 3e-4 + 1e-19, 2e-4, np.nan])  # two entries one round-off apart
    approximate = exact.copy()
    approximate[1] += 1e-19  # the screen ranks them the other way round
    approximate[2] -= 1e-19
    assert largest(approximate, lambda s: float(exact[s])) == exact[2]
    assert largest(np.full(3, np.nan), lambda s: float("nan")) == 0.0


def test_the_monitor_s_maxima_are_those_of_each_step_s_frames_taken_after_it():
    """The twin's frames are recorded from its next step's forward pass (the last one when read): the maxima are,
    to the bit, those of the frames computed after each step, across batches and with a read mid-run."""
    from cosim.coupling.arm_load import BATCH_STEPS, ArmLoadMonitor, rotation_angle
    from cosim.coupling.exchange import ROLES
    from cosim.frames import vector_norm

    scene = RobotScene.load()
    monitor = ArmLoadMonitor(scene)
    reference = mujoco.MjData(scene.model)  # the twin stepped alike, its frames computed after every step
    mujoco.mj_copyData(reference, scene.model, scene.data)
    body = {role: scene.arms[role].vessel_body for role in ROLES}
    scene.data.xfrc_applied[body[ArmRole.POUR]] = (0.0, 0.0, -30.0, 0.0, 0.5, 0.0)  # a load on the live pourer only
    position, rotation = dict.fromkeys(ROLES, 0.0), dict.fromkeys(ROLES, 0.0)
    for step in range(BATCH_STEPS + 60):
        targets = {role: (scene.arms[role].home_q + 1e-3 * step, np.full(len(scene.arms[role].joints), 0.5)) for role in ROLES}
        for role in ROLES:
            scene.set_joint_targets(role, *targets[role])
            reference.ctrl[scene.arms[role].ctrl_adr] = scene.servo_controls(role, *targets[role])
        for data in (scene.data, reference):
            mujoco.mj_step(scene.model, data)
            mujoco.mj_kinematics(scene.model, data)
        monitor.step(targets)
        for role in ROLES:
            live, twin = body[role], body[role]
            position[role] = max(position[role], float(vector_norm(scene.data.xpos[live] - reference.xpos[twin])))
            rotation[role] = max(rotation[role], rotation_angle(reference.xquat[twin], scene.data.xquat[live]))
        if step in (10, BATCH_STEPS - 1):  # read mid-run: the pending twin frames computed there
            assert monitor.max_position == position and monitor.max_rotation == rotation
    assert monitor.max_position == position and monitor.max_rotation == rotation
    assert position[ArmRole.POUR] > 1e-6 and rotation[ArmRole.POUR] > 1e-6  # the load moved the live pourer
