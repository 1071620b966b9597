"""How far a generated joint trajectory takes a vessel point (default: the lip) from the intended vessel path (m).

For each sample time ``t`` of the trajectory: the point's world position by forward kinematics of the arm's sampled
joint positions (MuJoCo, on a private ``MjData``), against the same point of the intended vessel pose at ``t - delay``
(``scene.vessel_target`` of the path's :class:`PlanarPose`). The point is given in the vessel frame; the default is
the pour lip, ``VesselSpec.lip_local``.
``delay`` is the generator's latency (:attr:`TrajectoryGenerator.latency`) for the tracking error proper, or 0 for
the plain time-aligned difference.
"""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np

from cosim.frames import quat_wxyz_to_matrix
from cosim.robots.planar import PlanarPose
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.joint_trajectory import JointTrajectory


def path_deviation(
    scene: RobotScene,
    role: ArmRole,
    trajectory: JointTrajectory,
    path: Callable[[float], PlanarPose],
    delay: float = 0.0,
    point_local: np.ndarray | None = None,
) -> np.ndarray:
    """(N,) m: distance between the vessel point moved by the trajectory and the same point on the path at
    ``t - delay``, per sample (see the module docstring). ``path(t)`` is the vessel's intended pose relative to home
    at time ``t`` s; ``point_local`` (3,) m in the vessel frame, default the lip."""
    arm = scene.arms[role]
    cols = trajectory.columns(arm.joints)
    point = arm.vessel.lip_local if point_local is None else np.asarray(point_local, dtype=float)
    data = mujoco.MjData(scene.model)
    data.qpos[:] = scene.data.qpos
    out = np.empty(trajectory.time.size)
    for i, (t, q) in enumerate(zip(trajectory.time, trajectory.positions[:, cols])):
        data.qpos[arm.qpos_adr] = q
        mujoco.mj_kinematics(scene.model, data)
        frame = data.site_xpos[arm.frame_site] + data.site_xmat[arm.frame_site].reshape(3, 3) @ point
        pos, quat = scene.vessel_target(role, path(float(t) - delay))
        out[i] = np.linalg.norm(frame - (pos + quat_wxyz_to_matrix(quat) @ point))
    return out
