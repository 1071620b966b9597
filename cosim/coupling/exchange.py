"""Pose and wrench exchange between the MuJoCo scene and the SPH solver (the coupling's frame conversions).

MuJoCo -> fluid: each vessel body's pose (``xpos``, ``xquat`` [w, x, y, z]) is the vessel frame of the fluid (the
scene generates the vessel bodies from the same :class:`VesselSpec`, frames coincide).
Fluid -> MuJoCo: the solver reports force and torque about the vessel's centre of mass from its
``VesselSpec`` (``com_local``), world frame; MuJoCo's ``xfrc_applied`` acts at the body's ``xipos``: the torque is
shifted to that point (they coincide for the generated vessels; a user's scene may differ).
"""

from __future__ import annotations

import numpy as np

from cosim.frames import Pose
from cosim.robots.scene import RobotScene, shift_wrench
from cosim.robots.scene_config import ArmRole

ROLES = (ArmRole.POUR, ArmRole.CATCH)  # fluid vessel index k <-> ROLES[k]


def vessel_poses(scene: RobotScene) -> list[Pose]:
    """World poses of the pourer and the catcher frames, in the fluid's vessel order (valid after mj_forward or
    mj_kinematics; read from the bodies' rows as they are: the Pose copies them)."""
    xpos, xquat, arms = scene.data.xpos, scene.data.xquat, scene.arms
    return [Pose.from_quat_wxyz(xpos[arms[role].vessel_body], xquat[arms[role].vessel_body]) for role in ROLES]


def wrench_at_body_com(scene: RobotScene, role: ArmRole, pose: Pose, wrench: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(force, torque) of a fluid wrench (6,) about the vessel spec's centre of mass, re-expressed about the MuJoCo
    body's centre of mass (world frame)."""
    spec_com = pose.transform(scene.arms[role].vessel.com_local[None, :])[0]
    body_com = scene.vessel_com(role)
    force = wrench[:3]
    return force, shift_wrench(force, wrench[3:], spec_com, body_com)
