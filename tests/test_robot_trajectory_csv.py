"""Trajectory CSV: exact round trip, one-line errors for corrupt files, atomic writes."""

from __future__ import annotations

import os

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.trajectory.csv_file import header, read_trajectory_csv, write_trajectory_csv
from cosim.trajectory.joint_trajectory import JointTrajectory

JOINTS = ("pour_arm/shoulder_pan", "pour_arm/elbow")


def _trajectory(n: int = 5) -> JointTrajectory:
    rng = np.random.default_rng(7)
    return JointTrajectory(
        time=np.linspace(0.0, 0.4, n) + 0.1,
        joint_names=JOINTS,
        positions=rng.normal(size=(n, 2)),
        velocities=rng.normal(size=(n, 2)),
        accelerations=rng.normal(size=(n, 2)) * 1e-7,
    )


def _write_text(tmp_path, text: str):
    path = tmp_path / "traj.csv"
    path.write_text(text)
    return path


def test_round_trip_is_exact(tmp_path):
    original = _trajectory()
    path = tmp_path / "sub" / "traj.csv"
    write_trajectory_csv(path, original)
    assert path.read_text().splitlines()[0] == ",".join(header(JOINTS))
    assert path.read_text().splitlines()[0].startswith("time,pour_arm/shoulder_pan.pos,pour_arm/shoulder_pan.vel,")
    loaded = read_trajectory_csv(path, known_joints=JOINTS)
    assert loaded.joint_names == JOINTS
    for field in ("time", "positions", "velocities", "accelerations"):
        np.testing.assert_array_equal(getattr(loaded, field), getattr(original, field))


GOOD_HEADER = ",".join(header(JOINTS))
GOOD_ROW = "0.0,1,0,0,2,0,0"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("", "empty file"),
        ("t,pour_arm/elbow.pos\n", "line 1: the first column must be 'time'"),
        ("time,pour_arm/elbow.pos\n0,1\n1,1\n", "lacks column(s) pour_arm/elbow.vel, pour_arm/elbow.acc"),
        ("time,pour_arm/elbow.speed\n", "column 'pour_arm/elbow.speed' is not <arm>/<joint>.pos|.vel|.acc"),
        (GOOD_HEADER.replace("pour_arm/elbow", "pour_arm/knee") + "\n" + GOOD_ROW + "\n", "unknown joint 'pour_arm/knee'"),
        (GOOD_HEADER + ",pour_arm/elbow.acc\n", "duplicate column 'pour_arm/elbow.acc'"),
        (GOOD_HEADER + "\n" + GOOD_ROW + "\n0.1,1,0,x,2,0,0\n", "line 3, column 'pour_arm/shoulder_pan.acc': 'x' is not a number"),
        (GOOD_HEADER + "\n" + GOOD_ROW + "\n0.1,1,0,0,nan,0,0\n", "line 3, column 'pour_arm/elbow.pos': 'nan' is not finite"),
        (GOOD_HEADER + "\n" + GOOD_ROW + "\n0.0,1,0,0,2,0,0\n", "line 3, column 'time': time 0.0 s does not increase"),
        (GOOD_HEADER + "\n" + GOOD_ROW + "\n0.1,1,0\n", "line 3: 3 values, the header has 7 columns"),
        (GOOD_HEADER + "\n" + GOOD_ROW + "\n", "1 data row(s), a trajectory needs at least 2"),
    ],
)
def test_corrupt_files_raise_one_line_input_errors(tmp_path, text, expected):
    path = _write_text(tmp_path, text)
    with pytest.raises(InputError) as info:
        read_trajectory_csv(path, known_joints=JOINTS)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(str(path)) and expected in message


def test_missing_file_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="file not found"):
        read_trajectory_csv(tmp_path / "absent.csv")


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    def failing_replace(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", failing_replace)
    with pytest.raises(OSError):
        write_trajectory_csv(tmp_path / "traj.csv", _trajectory())
    assert list(tmp_path.iterdir()) == []


def test_trajectory_validation():
    with pytest.raises(InputError, match="strictly increasing"):
        JointTrajectory(np.array([0.0, 0.0]), JOINTS, np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(InputError, match="must have shape"):
        JointTrajectory(np.array([0.0, 1.0]), JOINTS, np.zeros((2, 3)), np.zeros((2, 2)), np.zeros((2, 2)))
