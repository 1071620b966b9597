"""Joint trajectory MCAP: one ROS 2 ``trajectory_msgs/msg/JointTrajectory`` per arm, in rosbag2's MCAP storage
format (``ros2 bag play trajectory.mcap``; docs/ros2.md).

Layout: an MCAP file with the ``ros2`` profile, written with mcap-ros2-support; one schema
``trajectory_msgs/msg/JointTrajectory`` (encoding ``ros2msg``: the message definition followed by its dependencies,
each after a line of 80 ``=`` and ``MSG: <package>/<type>``, as rosbag2 records it); one channel per arm, topic
``/<arm>/joint_trajectory`` (``/pour_arm/joint_trajectory``), CDR-encoded, holding one message:

* ``header``: ``stamp`` 0 (a joint_trajectory_controller starts a trajectory stamped 0 when it receives it),
  ``frame_id`` empty;
* ``joint_names``: the arm's joints as its ROS 2 driver names them, with the scene's prefix
  (:mod:`cosim.trajectory.driver_names`), the same as trajectory.json's;
* ``points``: one ``JointTrajectoryPoint`` per sample (:mod:`cosim.trajectory.ros_points`): positions (rad),
  velocities (rad/s), accelerations (rad/s^2) as float64, equal to the CSV's; ``effort`` empty; ``time_from_start``
  the sample time rounded to the nanosecond.

The messages' log and publish times are 0 (the file holds no wall-clock time), so one run gives the same bytes every
time. :func:`trajectory_mcap_bytes` encodes everything in memory first (an encoding error writes nothing);
:func:`write_mcap_bytes` writes the result atomically (:mod:`cosim.atomic_files`).
"""

from __future__ import annotations

import io
from collections.abc import Mapping, Sequence
from pathlib import Path

from mcap_ros2.writer import Writer

from cosim.atomic_files import atomic_path
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.limits import ArmLimits
from cosim.trajectory.ros_points import arm_columns, check_driver_names, points

JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
_SEPARATOR = "=" * 80
# trajectory_msgs/msg/JointTrajectory with its dependencies (ROS 2 common_interfaces and rcl_interfaces, comments
# left out), in the concatenated form of the MCAP ros2msg schema encoding.
JOINT_TRAJECTORY_DEFINITION = f"""\
std_msgs/Header header
string[] joint_names
JointTrajectoryPoint[] points
{_SEPARATOR}
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
{_SEPARATOR}
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
{_SEPARATOR}
MSG: trajectory_msgs/JointTrajectoryPoint
float64[] positions
float64[] velocities
float64[] accelerations
float64[] effort
builtin_interfaces/Duration time_from_start
{_SEPARATOR}
MSG: builtin_interfaces/Duration
int32 sec
uint32 nanosec
"""


def topic(arm: str) -> str:
    """The topic of ``arm``'s trajectory, ``/<arm>/joint_trajectory``."""
    return f"/{arm}/joint_trajectory"


def trajectory_mcap_bytes(
    trajectory: JointTrajectory, limits: Sequence[ArmLimits], driver_names: Mapping[str, Sequence[str]]
) -> bytes:
    """The MCAP file of ``trajectory``: one message per arm of ``limits`` (their joints, in order, are its columns),
    joint names from ``driver_names`` (arm name -> names in the limits' order)."""
    check_driver_names(limits, driver_names)
    buffer = io.BytesIO()
    writer = Writer(buffer)
    schema = writer.register_msgdef(JOINT_TRAJECTORY, JOINT_TRAJECTORY_DEFINITION)
    for arm, cols in arm_columns(limits):
        message = {
            "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
            "joint_names": list(driver_names[arm.arm]),
            "points": [{**point, "effort": []} for point in points(trajectory, cols)],
        }
        writer.write_message(topic(arm.arm), schema, message, log_time=0, publish_time=0)
    writer.finish()
    return buffer.getvalue()


def write_mcap_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` (from :func:`trajectory_mcap_bytes`) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
