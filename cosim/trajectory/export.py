"""Write a run's joint trajectory files, only after the trajectory passed every check.

:func:`write_trajectory_files` runs :func:`cosim.trajectory.checks.check_trajectory` and builds the JSON text first:
an unsafe trajectory raises :class:`cosim.trajectory.checks.UnsafeTrajectoryError` and nothing is written. Then it
writes the CSV (:mod:`cosim.io.trajectory_csv`) and the JSON (:mod:`cosim.io.trajectory_json`), each atomically.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from cosim.io.trajectory_csv import JointTrajectory, write_trajectory_csv
from cosim.io.trajectory_json import trajectory_json_text, write_json_text
from cosim.trajectory.checks import TIME_TOLERANCE, check_trajectory
from cosim.trajectory.limits import ArmLimits


def write_trajectory_files(
    trajectory: JointTrajectory,
    limits: Sequence[ArmLimits],
    sample_rate_hz: float,
    csv_path: str | Path | None = None,
    json_path: str | Path | None = None,
) -> None:
    """Check ``trajectory`` against ``limits`` (one per arm, in column order), then write the CSV and/or the JSON.

    ``sample_rate_hz`` must match the trajectory's sample spacing (within the check's time tolerance).
    """
    check_trajectory(trajectory, limits)
    spacing = float(trajectory.time[1] - trajectory.time[0])
    if abs(spacing - 1.0 / sample_rate_hz) > TIME_TOLERANCE:
        raise ValueError(f"write_trajectory_files: samples are {spacing!r} s apart, not 1/{sample_rate_hz!r} Hz")
    text = trajectory_json_text(trajectory, limits, sample_rate_hz)  # validates the limits' joints before any write
    if csv_path is not None:
        write_trajectory_csv(csv_path, trajectory)
    if json_path is not None:
        write_json_text(json_path, text)
