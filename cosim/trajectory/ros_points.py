"""One arm of a sampled trajectory as ROS ``trajectory_msgs/JointTrajectoryPoint`` fields, shared by the JSON and
the MCAP exports so that both hold the same points and the same joint names (:func:`check_driver_names`).

A point is ``{"positions": [...], "velocities": [...], "accelerations": [...], "time_from_start": {"sec", "nanosec"}}``
(rad, rad/s, rad/s^2; the arm's joints in the trajectory's column order); ``time_from_start`` is the sample time
rounded to the nearest nanosecond (``builtin_interfaces/Duration``).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence

from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.limits import ArmLimits

NANOSECONDS = 1_000_000_000
POINT_FIELDS = ("positions", "velocities", "accelerations")  # JointTrajectoryPoint fields, JointTrajectory arrays order


def duration(t: float) -> dict[str, int]:
    """``builtin_interfaces/Duration`` of ``t`` >= 0 s, rounded to the nearest nanosecond."""
    ns = round(t * NANOSECONDS)
    return {"sec": ns // NANOSECONDS, "nanosec": ns % NANOSECONDS}


def check_driver_names(limits: Sequence[ArmLimits], driver_names: Mapping[str, Sequence[str]]) -> None:
    """ValueError unless ``driver_names`` gives every arm of ``limits`` one non-empty name per joint, unique per arm."""
    arms = [arm.arm for arm in limits]
    if list(driver_names) != arms:
        raise ValueError(f"JointTrajectory: driver joint names for arms {list(driver_names)}, the limits have {arms}")
    for arm in limits:
        names = list(driver_names[arm.arm])
        if len(names) != len(arm.joints) or len(set(names)) != len(names) or not all(isinstance(n, str) and n for n in names):
            raise ValueError(f"JointTrajectory: {arm.arm} needs {len(arm.joints)} unique driver joint names, got {names}")


def arm_columns(limits: Sequence[ArmLimits]) -> Iterator[tuple[ArmLimits, slice]]:
    """Each arm's limits with its columns in the trajectory (the arms' joints side by side, in ``limits`` order)."""
    start = 0
    for arm in limits:
        yield arm, slice(start, start + len(arm.joints))
        start += len(arm.joints)


def points(trajectory: JointTrajectory, columns: slice) -> list[dict]:
    """The ``JointTrajectoryPoint`` fields of the joints in ``columns``, one dict per sample."""
    if trajectory.time[0] < 0.0:
        raise ValueError("JointTrajectoryPoint: time_from_start cannot be negative")
    blocks = [trajectory.positions[:, columns], trajectory.velocities[:, columns], trajectory.accelerations[:, columns]]
    return [
        {**{f: [float(v) for v in b[i]] for f, b in zip(POINT_FIELDS, blocks)}, "time_from_start": duration(float(t))}
        for i, t in enumerate(trajectory.time)
    ]
