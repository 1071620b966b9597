"""Write a run's joint trajectory files, only after the trajectory passed every check.

:func:`write_trajectory_files` runs :func:`cosim.trajectory.checks.check_trajectory` and builds the JSON text and the
MCAP bytes first: an unsafe trajectory raises :class:`cosim.trajectory.checks.UnsafeTrajectoryError` and nothing is
written. Then it writes the CSV (:mod:`cosim.trajectory.csv_file`), the JSON (:mod:`cosim.trajectory.json_file`) and the
MCAP (:mod:`cosim.trajectory.mcap_file`), each atomically.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from cosim.trajectory.checks import TIME_TOLERANCE, check_trajectory
from cosim.trajectory.csv_file import write_trajectory_csv
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.json_file import trajectory_json_text, write_json_text
from cosim.trajectory.limits import ArmLimits


def write_trajectory_files(
    trajectory: JointTrajectory,
    limits: Sequence[ArmLimits],
    sample_rate_hz: float,
    driver_names: Mapping[str, Sequence[str]],
    csv_path: str | Path | None = None,
    json_path: str | Path | None = None,
    mcap_path: str | Path | None = None,
) -> None:
    """Check ``trajectory`` against ``limits`` (one per arm, in column order), then write the CSV, the JSON and/or
    the MCAP. ``driver_names``: arm name -> its joints as the arm's ROS 2 driver names them (the JSON's and the
    MCAP's joint names; :func:`cosim.trajectory.driver_names.driver_joint_names`).

    ``sample_rate_hz`` must match the trajectory's sample spacing (within the check's time tolerance).
    """
    check_trajectory(trajectory, limits)
    spacing = float(trajectory.time[1] - trajectory.time[0])
    if abs(spacing - 1.0 / sample_rate_hz) > TIME_TOLERANCE:
        raise ValueError(f"write_trajectory_files: samples are {spacing!r} s apart, not 1/{sample_rate_hz!r} Hz")
    text = trajectory_json_text(trajectory, limits, sample_rate_hz, driver_names)  # validates the joints and names
    data = b""
    if mcap_path is not None:  # mcap-ros2-support imported only where the MCAP is written
        from cosim.trajectory.mcap_file import trajectory_mcap_bytes, write_mcap_bytes

        data = trajectory_mcap_bytes(trajectory, limits, driver_names)
    if csv_path is not None:
        write_trajectory_csv(csv_path, trajectory)
    if json_path is not None:
        write_json_text(json_path, text)
    if mcap_path is not None:
        write_mcap_bytes(mcap_path, data)
