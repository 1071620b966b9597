"""``cosim replay``: JSON output and PASS of a good trajectory; FAIL with its reasons and exit status 1 for one the
servos cannot track; one line and exit status 2 for bad input."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from cosim.cli.main import main
from cosim.robots.scene import RobotScene
from cosim.trajectory.csv_file import write_trajectory_csv
from cosim.trajectory.joint_trajectory import JointTrajectory


def _two_samples(path, lift: float):
    """A 0.2 s trajectory from home to home with the pour arm's shoulder lift turned by ``lift`` rad, at rest at both
    ends."""
    scene = RobotScene.load()
    names = tuple(n for arm in scene.arms.values() for n in arm.joints)
    q = np.concatenate([arm.home_q for arm in scene.arms.values()])
    end = q.copy()
    end[names.index("pour_arm/shoulder_lift")] += lift
    zeros = np.zeros((2, q.size))
    write_trajectory_csv(path, JointTrajectory(np.array([0.0, 0.2]), names, np.vstack((q, end)), zeros, zeros))
    return path


@pytest.fixture(scope="module")
def hold_csv(tmp_path_factory):
    return _two_samples(tmp_path_factory.mktemp("cli") / "hold.csv", 0.0)


def test_replay_json(hold_csv, capsys):
    assert main(["replay", str(hold_csv), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["max_error_m"] < 1e-6
    assert len(result["joint_max_error_rad"]) == 12 and "pour_arm/shoulder_pan" in result["joint_max_error_rad"]
    assert result["first_contact"] is None
    assert (result["verdict"], result["tolerance_m"], result["failures"]) == ("pass", 0.002, [])


def test_replay_table(hold_csv, capsys):
    assert main(["replay", str(hold_csv), "--payload", "empty"]) == 0
    out = capsys.readouterr().out
    assert "pourer lip path error" in out and "contacts: none" in out
    assert out.splitlines()[-1] == "PASS: every vessel lip within 2.000 mm of its commanded path, no contact"


def test_replay_of_a_move_the_servos_cannot_track_fails_with_its_reasons_and_exit_1(tmp_path, capsys):
    # 0.6 rad of shoulder lift in 0.2 s: the servos saturate even with the motion's inverse dynamics fed forward (the
    # default), the pourer's lip falls centimetres behind its path and the pourer hits the catcher
    path = _two_samples(tmp_path / "fast.csv", 0.6)
    assert main(["replay", str(path), "--json", "--tolerance-mm", "3"]) == 1
    result = json.loads(capsys.readouterr().out)
    assert result["verdict"] == "fail" and result["tolerance_m"] == 0.003
    assert result["lip_max_error_m"]["pourer"] > 0.003 and result["first_contact"] is not None
    reasons = result["failures"]
    assert re.fullmatch(r"pourer lip path error \d+\.\d{3} mm \(at t=\d+\.\d{3} s\) above 3\.000 mm", reasons[0])
    assert reasons[-1].startswith("contact at t=")
    assert all(r.startswith("catcher lip") for r in reasons[1:-1])
    assert (len(reasons) == 3) == (result["lip_max_error_m"]["catcher"] > 0.003)
    assert main(["replay", str(path)]) == 1
    assert capsys.readouterr().out.splitlines()[-1].startswith("FAIL: pourer lip path error ")


def test_replay_tolerance_out_of_range_exits_2_with_one_line(hold_csv, capsys):
    assert main(["replay", str(hold_csv), "--tolerance-mm", "0"]) == 2
    captured = capsys.readouterr()
    assert captured.err.strip() == "cosim replay: error: --tolerance-mm: must be in (0, 1000] mm, got 0"
    assert captured.out == ""


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


def _with(path, column: str, row: int, value: float):
    """A copy of the two-sample trajectory at ``path`` with one entry set: ``column`` of sample ``row``."""
    from cosim.trajectory.csv_file import read_trajectory_csv

    t = read_trajectory_csv(path)
    kind, name = column.rsplit(".", 1)[1], column.rsplit(".", 1)[0]
    arrays = {"pos": t.positions.copy(), "vel": t.velocities.copy(), "acc": t.accelerations.copy()}
    arrays[kind][row, t.joint_names.index(name)] = value
    out = path.with_name(f"{column.replace('/', '_')}.csv")
    write_trajectory_csv(out, JointTrajectory(t.time, t.joint_names, arrays["pos"], arrays["vel"], arrays["acc"]))
    return out


@pytest.mark.parametrize(
    ("column", "value", "expected"),
    [
        ("pour_arm/elbow.pos", 100.0, r"pour_arm/elbow\.pos: must be in \[-\S+, \S+\] rad \(the joint's range\), got 100 at t = 0\.2 s"),
        ("catch_arm/wrist_1.vel", -1e6, r"catch_arm/wrist_1\.vel: must be within \+-\S+ rad/s \(the arm's joint speed limit\), got -1e\+06 at t = 0\.2 s"),
    ],
)
def test_replay_of_a_trajectory_past_the_arms_limits_is_refused_before_it_runs(hold_csv, capsys, column, value, expected):
    # MuJoCo driven there would blow up and the replay report it as a failed run (exit 1), after the run
    path = _with(hold_csv, column, 1, value)
    assert main(["replay", str(path)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and re.search(expected, lines[0]), lines
    assert captured.out == ""


def test_replay_model_that_is_a_folder_says_so(hold_csv, tmp_path, capsys):
    assert main(["replay", str(hold_csv), "--model", str(tmp_path)]) == 2
    assert "a folder, not a scene file" in capsys.readouterr().err
