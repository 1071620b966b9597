"""``cosim replay``: JSON output of a good trajectory; one line and exit status 2 for bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cosim.cli.main import main
from cosim.io.trajectory_csv import JointTrajectory, write_trajectory_csv
from cosim.robots.scene import RobotScene


@pytest.fixture(scope="module")
def hold_csv(tmp_path_factory):
    scene = RobotScene.load()
    names = tuple(n for arm in scene.arms.values() for n in arm.joints)
    q = np.concatenate([arm.home_q for arm in scene.arms.values()])
    zeros = np.zeros((2, q.size))
    path = tmp_path_factory.mktemp("cli") / "hold.csv"
    write_trajectory_csv(path, JointTrajectory(np.array([0.0, 0.2]), names, np.vstack((q, q)), zeros, zeros))
    return path


def test_replay_json(hold_csv, capsys):
    assert main(["replay", str(hold_csv), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["max_error_m"] < 1e-6
    assert len(result["joint_max_error_rad"]) == 12 and "pour_arm/shoulder_pan" in result["joint_max_error_rad"]
    assert result["first_contact"] is None


def test_replay_table(hold_csv, capsys):
    assert main(["replay", str(hold_csv), "--payload", "empty"]) == 0
    out = capsys.readouterr().out
    assert "pourer lip path error" in out and "contacts: none" in out


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("time,pour_arm/elbow.pos,pour_arm/elbow.vel\n0,0,0\n", "lacks column(s) pour_arm/elbow.acc"),
        ("time,arm9/elbow.pos,arm9/elbow.vel,arm9/elbow.acc\n0,0,0,0\n1,0,0,0\n", "unknown joint 'arm9/elbow'"),
        (None, "file not found"),
    ],
)
def test_replay_bad_input_exits_2_with_one_line(tmp_path, capsys, content, expected):
    path = tmp_path / "bad.csv"
    if content is not None:
        path.write_text(content)
    assert main(["replay", str(path)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cosim replay: error: ") and expected in lines[0]
    assert captured.out == ""


def test_replay_bad_model_exits_2(hold_csv, tmp_path, capsys):
    assert main(["replay", str(hold_csv), "--model", str(tmp_path / "none.xml")]) == 2
    assert "file not found" in capsys.readouterr().err
