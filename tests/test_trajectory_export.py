"""Exported trajectory files: independent differentiation of the CSV, replay in MuJoCo, JSON = CSV = MCAP (read back
with the mcap reader), the arms' driver joint names, unsafe refused.

The differentiation test uses nothing of cosim.trajectory: it reads the files back and checks them against the
limits stored in the JSON.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from cosim.cli.main import main
from cosim.errors import InputError
from cosim.robots.assets import DEFAULT_SCENE, models_dir
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.checks import UnsafeTrajectoryError
from cosim.trajectory.csv_file import read_trajectory_csv
from cosim.trajectory.driver_names import JointPrefix, driver_joint_names
from cosim.trajectory.export import write_trajectory_files
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.json_file import FORMAT, UNITS, read_trajectory_json
from cosim.trajectory.limits import JointLimitOverride, arm_limits
from cosim.trajectory.scripted import generate_scripted, pour_poses

# Acceptance: `cosim replay trajectory.csv` tracks the vessel path within 2 mm.
MAX_REPLAY_ERROR_M = 2e-3
# Relative slack on the limits for round-off (the files hold ruckig's output exactly).
LIMIT_RTOL = 1e-9
# JSON time_from_start is the sample time rounded to the nanosecond.
JSON_TIME_RESOLUTION = 0.5e-9
EPS = np.finfo(float).eps
# The default prefixes before the UR driver's joint names (the scene does not change them).
NAMES = {arm: tuple(f"{arm}_{j}_joint" for j in ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"))
         for arm in ("pour_arm", "catch_arm")}


@pytest.fixture(scope="module")
def exported(scene, tmp_path_factory, scripted_pour):
    run = scripted_pour
    folder = tmp_path_factory.mktemp("pour")
    write_trajectory_files(run.trajectory, run.limits, run.sample_rate_hz, driver_joint_names(scene, JointPrefix()),
                           folder / "trajectory.csv", folder / "trajectory.json", folder / "trajectory.mcap")
    return run, folder


def _json_limits(folder, trajectory: JointTrajectory) -> dict[str, np.ndarray]:
    """Per limit field, (J,) values in the CSV's column order, read from the JSON file directly."""
    document = json.loads((folder / "trajectory.json").read_text())
    per_joint = {}
    for arm in document["arms"].values():
        for i, name in enumerate(arm["scene_joint_names"]):
            per_joint[name] = {field: values[i] for field, values in arm["limits"].items()}
    return {field: np.array([per_joint[n][field] for n in trajectory.joint_names])
            for field in ("max_velocity", "max_acceleration", "max_jerk", "min_position", "max_position")}


def _differentiation_errors(trajectory: JointTrajectory) -> tuple[np.ndarray, np.ndarray]:
    """Central differences of the positions minus the velocity and acceleration columns at the interior samples."""
    q, h = trajectory.positions, float(trajectory.time[1] - trajectory.time[0])
    velocity = (q[2:] - q[:-2]) / (2.0 * h)
    acceleration = (q[2:] - 2.0 * q[1:-1] + q[:-2]) / (h * h)
    return velocity - trajectory.velocities[1:-1], acceleration - trajectory.accelerations[1:-1]


def _differentiation_bounds(trajectory: JointTrajectory, max_jerk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Largest admissible differentiation errors (J,) for a motion with |jerk| <= max_jerk sampled at spacing h.

    Over [t - h, t + h] write v(t + s) = v + a s + r(s) with |r| <= J s^2 / 2: the central difference averages v, the
    odd term cancels, so |D1 - v| <= J h^2 / 6. The second difference is the triangle-weighted mean of a over
    [t - h, t + h] and |a(t + s) - a(t)| <= J |s|, so |D2 - a| <= J h / 3. Round-off of positions |q| adds
    2 eps |q| / h and 4 eps |q| / h^2 (h is the spacing of the file's times; the differences round at most that).
    """
    h = float(trajectory.time[1] - trajectory.time[0])
    scale = np.abs(trajectory.positions).max(axis=0)
    return max_jerk * h * h / 6.0 + 2.0 * EPS * scale / h, max_jerk * h / 3.0 + 4.0 * EPS * scale / (h * h)


def test_exported_positions_differentiate_to_the_velocity_and_acceleration_columns(exported):
    _, folder = exported
    trajectory = read_trajectory_csv(folder / "trajectory.csv")
    limits = _json_limits(folder, trajectory)
    h = float(trajectory.time[1] - trajectory.time[0])
    assert h == pytest.approx(1.0 / 500.0, abs=1e-12)
    np.testing.assert_allclose(np.diff(trajectory.time), h, rtol=0.0, atol=1e-12)
    velocity_error, acceleration_error = _differentiation_errors(trajectory)
    velocity_bound, acceleration_bound = _differentiation_bounds(trajectory, limits["max_jerk"])
    assert np.all(np.abs(velocity_error) <= velocity_bound), np.abs(velocity_error).max(axis=0)
    assert np.all(np.abs(acceleration_error) <= acceleration_bound), np.abs(acceleration_error).max(axis=0)
    # the check has teeth: a velocity column one sample late is caught
    late = JointTrajectory(trajectory.time, trajectory.joint_names, trajectory.positions,
                           np.roll(trajectory.velocities, 1, axis=0), trajectory.accelerations)
    assert np.any(np.abs(_differentiation_errors(late)[0]) > velocity_bound)
    # every limit holds
    tol = 1.0 + LIMIT_RTOL
    assert np.all(np.abs(trajectory.velocities) <= limits["max_velocity"] * tol)
    assert np.all(np.abs(trajectory.accelerations) <= limits["max_acceleration"] * tol)
    assert np.all(np.abs(np.diff(trajectory.accelerations, axis=0)) / h <= limits["max_jerk"] * tol)
    assert np.all(trajectory.positions >= limits["min_position"]) and np.all(trajectory.positions <= limits["max_position"])
    # the motion is a real pour: a pour-arm joint turns by more than 90 deg; it starts and ends at rest
    pour_arm = [i for i, name in enumerate(trajectory.joint_names) if name.startswith("pour_arm/")]
    assert np.ptp(trajectory.positions[:, pour_arm], axis=0).max() > math.radians(90.0)
    assert np.abs(trajectory.velocities[[0, -1]]).max() <= 1e-12


def test_cosim_replay_tracks_the_exported_pour(exported, capsys):
    _, folder = exported
    assert main(["replay", str(folder / "trajectory.csv"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["max_error_m"] <= MAX_REPLAY_ERROR_M
    assert report["first_contact"] is None
    assert report["duration_s"] == pytest.approx(10.0, abs=0.05)


def test_json_and_csv_hold_the_same_numbers(exported):
    run, folder = exported
    csv = read_trajectory_csv(folder / "trajectory.csv")
    document = read_trajectory_json(folder / "trajectory.json")
    assert document.sample_rate_hz == 500.0
    assert document.limits == run.limits
    assert document.trajectory.joint_names == csv.joint_names
    np.testing.assert_allclose(document.trajectory.time, csv.time, rtol=0.0, atol=JSON_TIME_RESOLUTION)
    for field in ("positions", "velocities", "accelerations"):
        np.testing.assert_array_equal(getattr(document.trajectory, field), getattr(csv, field))
        np.testing.assert_array_equal(getattr(csv, field), getattr(run.trajectory, field))
    raw = json.loads((folder / "trajectory.json").read_text())
    assert raw["format"] == FORMAT and raw["units"] == UNITS
    assert list(raw["arms"]) == ["pour_arm", "catch_arm"]
    point = raw["arms"]["pour_arm"]["points"][1]
    assert set(point) == {"positions", "velocities", "accelerations", "time_from_start"}
    assert point["time_from_start"] == {"sec": 0, "nanosec": 2_000_000}
    assert raw["arms"]["catch_arm"]["arm_model"] == "UR10e"
    # ROS 2 users get the UR driver's joint names with the arm's prefix; the scene's names map them onto the CSV
    assert document.driver_joint_names == NAMES
    assert {arm: tuple(raw["arms"][arm]["joint_names"]) for arm in raw["arms"]} == NAMES
    assert tuple(n for arm in raw["arms"].values() for n in arm["scene_joint_names"]) == csv.joint_names


def test_mcap_holds_one_joint_trajectory_per_arm_equal_to_the_csv(exported):
    _, folder = exported
    csv = read_trajectory_csv(folder / "trajectory.csv")
    with (folder / "trajectory.mcap").open("rb") as handle:
        reader = make_reader(handle, decoder_factories=[DecoderFactory()])
        profile = reader.get_header().profile
        messages = [(schema, channel, message, ros) for schema, channel, message, ros in reader.iter_decoded_messages()]
    assert profile == "ros2"
    assert [channel.topic for _, channel, _, _ in messages] == ["/pour_arm/joint_trajectory", "/catch_arm/joint_trajectory"]
    for schema, channel, message, ros in messages:
        arm = channel.topic.split("/")[1]
        assert (schema.name, schema.encoding, channel.message_encoding) == ("trajectory_msgs/msg/JointTrajectory", "ros2msg", "cdr")
        assert message.log_time == 0 and (ros.header.stamp.sec, ros.header.stamp.nanosec, ros.header.frame_id) == (0, 0, "")
        assert tuple(ros.joint_names) == NAMES[arm]
        assert len(ros.points) == csv.time.size
        columns = [i for i, name in enumerate(csv.joint_names) if name.startswith(f"{arm}/")]  # base to tip
        for field in ("positions", "velocities", "accelerations"):
            np.testing.assert_array_equal(np.array([getattr(p, field) for p in ros.points]), getattr(csv, field)[:, columns])
        assert all(len(p.effort) == 0 for p in ros.points)
        stamps = np.array([p.time_from_start.sec + p.time_from_start.nanosec * 1e-9 for p in ros.points])
        np.testing.assert_allclose(stamps, csv.time, rtol=0.0, atol=JSON_TIME_RESOLUTION + 1e-15)


def test_joint_prefixes_name_the_exported_joints(scene):
    names = driver_joint_names(scene, JointPrefix(pour_arm="", catch_arm="bob_"))
    assert names["pour_arm"] == tuple(n.removeprefix("pour_arm_") for n in NAMES["pour_arm"])
    assert names["catch_arm"] == tuple(n.replace("catch_arm_", "bob_") for n in NAMES["catch_arm"])


@pytest.mark.parametrize("prefix", ["2nd_", "ur-", "alice/", "a" * 65, 3])
def test_a_bad_joint_prefix_is_refused_in_one_line(prefix):
    with pytest.raises(InputError, match=r"^trajectory\.joint_prefix\.catch_arm: must be a letter followed by letters, digits or '_'"):
        JointPrefix(catch_arm=prefix)


def test_a_scene_file_without_driver_names_exports_the_mjcf_names(tmp_path):
    # a scene written before the builder recorded the drivers' names: the arm's MJCF joint names are exported
    text = (models_dir() / DEFAULT_SCENE).read_text()
    lines = [line for line in text.splitlines() if "/driver_joints" not in line]
    assert len(lines) == len(text.splitlines()) - 2
    path = tmp_path / "scene.xml"
    path.write_text("\n".join(lines))
    names = driver_joint_names(RobotScene.load(path), JointPrefix())
    assert names["pour_arm"][0] == "pour_arm_shoulder_pan" and names["catch_arm"][-1] == "catch_arm_wrist_3"


def test_same_run_gives_byte_identical_files(scene, exported, tmp_path, scripted_pour_spec):
    _, folder = exported
    again = generate_scripted(scene, pour_poses(scene, scripted_pour_spec))
    write_trajectory_files(again.trajectory, again.limits, again.sample_rate_hz, driver_joint_names(scene, JointPrefix()),
                           tmp_path / "t.csv", tmp_path / "t.json", tmp_path / "t.mcap")
    for suffix in ("csv", "json", "mcap"):
        assert (tmp_path / f"t.{suffix}").read_bytes() == (folder / f"trajectory.{suffix}").read_bytes()


def _corrupt(trajectory: JointTrajectory, how: str) -> JointTrajectory:
    q, v, a, t = (trajectory.positions.copy(), trajectory.velocities.copy(), trajectory.accelerations.copy(),
                  trajectory.time.copy())
    i = 2500  # t = 5 s
    if how == "position jump":
        q[i:, 2] += 0.01
    elif how == "velocity jump":
        v[i:, 2] += 0.05
    elif how == "acceleration spike":
        a[i, 2] = 6.0
    elif how == "out of range":
        q[:, 9] -= 2.0  # catch_arm/wrist_1 starts at -4.54 rad
    elif how == "uneven time":
        t[i:] += 0.0005
    fixed = JointTrajectory(t, trajectory.joint_names, q, v, a)
    if how == "not finite":  # arrays stay mutable after validation
        fixed.accelerations[i, 2] = math.nan
    return fixed


@pytest.mark.parametrize(
    ("how", "message"),
    [
        # the 0.01 rad jump plus the path's own step there (at the pour's peak, a fraction of a micro-radian either way)
        ("position jump", r"arm pour_arm, joint elbow, t=4\.9980 s: \|position step\| 0\.0(09999|1)\d* rad above max_velocity \* h 0\.00628318 rad$"),
        ("velocity jump", r"arm pour_arm, joint elbow, t=4\.9980 s: \|velocity step\| 0\.05\d* rad/s above max_acceleration \* h 0\.01 rad/s$"),
        ("acceleration spike", r"arm pour_arm, joint elbow, t=5\.0000 s: \|acceleration\| 6 rad/s\^2 above max_acceleration 5 rad/s\^2$"),
        ("out of range", r"arm catch_arm, joint wrist_1, t=0\.0000 s: position -6\.5\d+ rad below min_position -6\.28319 rad$"),
        ("uneven time", r"time is not strictly increasing and uniform: step 0\.0025 s at t=4\.9980 s, the first step is 0\.002 s$"),
        ("not finite", r"arm pour_arm, joint elbow, t=5\.0000 s: acceleration is not finite$"),
    ],
)
def test_unsafe_trajectory_is_refused_and_nothing_written(exported, tmp_path, how, message):
    run, _ = exported
    bad = _corrupt(run.trajectory, how)
    with pytest.raises(UnsafeTrajectoryError, match=r"^unsafe trajectory: " + message) as info:
        write_trajectory_files(bad, run.limits, run.sample_rate_hz, NAMES, tmp_path / "trajectory.csv",
                               tmp_path / "trajectory.json", tmp_path / "trajectory.mcap")
    assert "\n" not in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_driver_names_that_do_not_fit_the_arms_are_refused_and_nothing_written(exported, tmp_path):
    run, _ = exported
    short = {**NAMES, "catch_arm": NAMES["catch_arm"][:-1]}
    with pytest.raises(ValueError, match=r"^JointTrajectory: catch_arm needs 6 unique driver joint names"):
        write_trajectory_files(run.trajectory, run.limits, run.sample_rate_hz, short, tmp_path / "trajectory.csv",
                               tmp_path / "trajectory.json", tmp_path / "trajectory.mcap")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("override", "message"),
    [
        (JointLimitOverride(max_velocity=0.2), r"\|velocity\| 0\.2\d* rad/s above max_velocity 0\.2 rad/s$"),
        (JointLimitOverride(max_acceleration=0.5), r"\|acceleration\| 0\.5\d* rad/s\^2 above max_acceleration 0\.5 rad/s\^2$"),
        # the pour needs 2.03 rad/s^3 on wrist_1
        (JointLimitOverride(max_jerk=2.0), r"\|jerk \(acceleration difference / h\)\| 2\.0\d* rad/s\^3 above max_jerk 2 rad/s\^3$"),
    ],
)
def test_tighter_limits_refuse_the_pour(scene, exported, tmp_path, override, message):
    run, _ = exported
    tight = [arm_limits(scene, role, {"wrist_1": override}) for role in ArmRole]
    with pytest.raises(UnsafeTrajectoryError, match=r"^unsafe trajectory: arm pour_arm, joint wrist_1, t=\d+\.\d{4} s: " + message):
        write_trajectory_files(run.trajectory, tight, run.sample_rate_hz, NAMES, tmp_path / "trajectory.csv")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d.update(format="ros"), r"format: must be 'cosim.joint_trajectory.v2', got 'ros'$"),
        (lambda d: d["arms"]["pour_arm"]["points"][3].update(positions=[0.0]), r"arms\.pour_arm\.points\[3\]\.positions: must be a list of 6 finite numbers$"),
        (lambda d: d["arms"]["catch_arm"]["points"][2]["time_from_start"].update(nanosec=-1), r"arms\.catch_arm\.points\[2\]\.time_from_start: sec must be an integer >= 0"),
        (lambda d: d["arms"]["catch_arm"]["points"][2]["time_from_start"].update(nanosec=3_000_000), r"arms\.catch_arm\.points: the times differ from the first arm's$"),
        (lambda d: d["arms"]["pour_arm"]["limits"]["max_jerk"].__setitem__(0, -1.0), r"limits\.pour_arm/shoulder_pan\.max_jerk: must be in \(0, 1e\+06\] rad/s\^3, got -1$"),
        (lambda d: d["arms"]["pour_arm"].pop("joint_names"), r"arms\.pour_arm: missing key\(s\) joint_names$"),
        (lambda d: d["arms"]["pour_arm"]["joint_names"].pop(), r"arms\.pour_arm\.joint_names: must be a non-empty list of 6 unique names$"),
    ],
)
def test_corrupt_json_is_rejected_in_one_line(exported, tmp_path, edit, message):
    _, folder = exported
    document = json.loads((folder / "trajectory.json").read_text())
    document["arms"]["pour_arm"]["points"] = document["arms"]["pour_arm"]["points"][:5]
    document["arms"]["catch_arm"]["points"] = document["arms"]["catch_arm"]["points"][:5]
    edit(document)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(document))
    with pytest.raises(InputError, match=r"^" + str(path).replace(".", r"\.") + ": " + message) as info:
        read_trajectory_json(path)
    assert "\n" not in str(info.value)


def test_unreadable_json_is_rejected_in_one_line(tmp_path):
    path = tmp_path / "t.json"
    path.write_text('{"format": ')
    with pytest.raises(InputError, match=r": not a readable JSON file \(Expecting value: line 1 column 12 \(char 11\)\)$"):
        read_trajectory_json(path)
    with pytest.raises(InputError, match=r"missing\.json: file not found$"):
        read_trajectory_json(tmp_path / "missing.json")
