"""The joint names of the exported trajectories: each arm's joints as its ROS 2 driver names them, with a prefix.

A ROS 2 driver names an arm's joints after its robot description (Universal Robots: ``shoulder_pan_joint`` ...
``wrist_3_joint``, :mod:`cosim.robots.ur10e`); a cell that describes several arms in one robot description puts a
prefix before each arm's names (the UR driver's ``tf_prefix``, e.g. ``alice_shoulder_pan_joint``). The arm model
gives the names (:attr:`cosim.robots.scene.ArmInfo.driver_joints`); :class:`JointPrefix` (scene section
``[trajectory.joint_prefix]``) gives each arm's prefix. The scene's own names (``pour_arm/shoulder_pan``) stay the
CSV's columns; trajectory.json and trajectory.mcap use these.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from cosim.checks import check_ros_name
from cosim.robots.scene_config import ArmRole

if TYPE_CHECKING:
    from cosim.robots.scene import RobotScene


@dataclass(frozen=True)
class JointPrefix:
    """pour_arm: put before the pour arm's joint names in trajectory.json and trajectory.mcap, as the ROS 2 driver's
      tf_prefix ('pour_arm_shoulder_pan_joint'); '' for an arm driven with an empty tf_prefix. [a letter, then
      letters, digits or '_', at most 64 characters; or '']
    catch_arm: the same for the catch arm. [as pour_arm]
    """

    pour_arm: str = f"{ArmRole.POUR.value}_"
    catch_arm: str = f"{ArmRole.CATCH.value}_"

    def __post_init__(self) -> None:
        for role in ArmRole:
            check_ros_name(f"trajectory.joint_prefix.{role.value}", getattr(self, role.value), allow_empty=True)


def driver_joint_names(scene: RobotScene, prefix: JointPrefix) -> dict[str, tuple[str, ...]]:
    """Arm name -> its joints, base to tip, as its ROS 2 driver names them, each after the arm's ``prefix``; arms in
    :class:`ArmRole` order (the trajectory files' order)."""
    return {role.value: tuple(getattr(prefix, role.value) + name for name in scene.arms[role].driver_joints) for role in ArmRole}
