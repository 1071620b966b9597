"""``python -m cosim.tools.pour_motion`` and ``python -m cosim.tools.scripted_pour``: a short motion is written and
reads back; bad input is one line and exit 2 with nothing written."""

from __future__ import annotations

import pytest

from cosim.tools import pour_motion, scripted_pour
from cosim.trajectory.csv_file import read_trajectory_csv

SHORT = ["--duration", "6", "--tilt-deg", "40"]  # s, deg: within the joint limits and cheap to plan


def test_pour_motion_writes_a_trajectory_that_reads_back(tmp_path, capsys):
    out = tmp_path / "pour.csv"
    assert pour_motion.main(["--out", str(out), *SHORT]) == 0
    trajectory = read_trajectory_csv(out)
    assert trajectory.duration == pytest.approx(6.0) and len(trajectory.joint_names) == 12
    assert f"wrote {out}" in capsys.readouterr().out


@pytest.mark.parametrize("tool", [pour_motion, scripted_pour])
def test_bad_duration_exits_2_with_one_line_and_writes_nothing(tool, tmp_path, capsys):
    out = tmp_path / ("pour.csv" if tool is pour_motion else "run")
    assert tool.main(["--out", str(out), "--duration", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "duration" in err and "[1, 120]" in err
    assert not out.exists()
