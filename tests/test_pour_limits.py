"""`cosim pour` with a user's joint limit 1 % below what the (coarse, short) pour needs stops at the first target
beyond it: one line naming arm, joint, time and limit, exit 1, nothing written."""

from __future__ import annotations

import re

import numpy as np

from cosim.cli.main import main
from cosim.trajectory.csv_file import read_trajectory_csv

COARSE = """
name = "limits"
[fluid]
particles_across = 10
[coupling]
max_duration = 0.8
"""
JOINT = "pour_arm/wrist_1"  # the pour arm's fastest joint over this pour's first 0.8 s
USER_LIMIT_FRACTION = 0.99
CONTROL_PERIOD = 0.01  # s: targets, and so the path's velocity, come this often


def test_a_limit_below_the_pours_need_stops_the_run_at_once_naming_it(tmp_path, capsys):
    scene = tmp_path / "pour.toml"
    scene.write_text(COARSE)
    assert main(["pour", str(scene), "--out", str(tmp_path / "free"), "--quiet", "--no-log"]) == 0
    trajectory = read_trajectory_csv(tmp_path / "free" / "trajectory.csv")
    speed = np.abs(trajectory.velocities[:, trajectory.joint_names.index(JOINT)])
    limit = USER_LIMIT_FRACTION * float(speed.max())
    first_beyond = float(trajectory.time[np.argmax(speed > limit)])

    limited = tmp_path / "limited.toml"
    limited.write_text(COARSE + f'[trajectory.limits."{JOINT}"]\nmax_velocity = {limit!r}\n')
    capsys.readouterr()
    assert main(["pour", str(limited), "--out", str(tmp_path / "limited"), "--quiet", "--no-log"]) == 1
    err = capsys.readouterr().err.strip()
    assert "\n" not in err
    found = re.fullmatch(
        r"cosim pour: simulation failed: untrackable path: arm pour_arm, joint wrist_1, t=([0-9.]+) s: the target path "
        r"moves at ([0-9.]+) rad/s, above max_velocity ([0-9.]+) rad/s",
        err,
    )
    assert found, err
    assert float(found.group(3)) == float(f"{limit:.6g}")
    # at the target where the arm first needed more: the target that starts the spline segment it is exceeded in
    # (1e-9 s: the round-off of the two printed times' difference)
    assert abs(float(found.group(1)) - first_beyond) <= CONTROL_PERIOD + 1e-9
    assert not (tmp_path / "limited").exists()
