"""The joint torques a real arm needs to run a trajectory while holding the liquid: inverse dynamics.

For each sample of a joint trajectory (positions, velocities, accelerations of every joint of the scene's arms)
``mujoco.mj_inverse`` gives ``qfrc_inverse = M(q) qdd + c(q, qd)`` (rigid-body dynamics of arm and vessel, rotor
inertia (armature) and gravity included, passive forces not), the generalised force all actuators and external forces
together must supply. The liquid supplies ``J^T w`` of it (``w`` its measured wrench on the vessel, ``J`` the
vessel body's Jacobian at its centre of mass), so the drives must deliver

    tau = qfrc_inverse - J^T w    (N m per joint).

:func:`cosim.trajectory.checks.check_torques` checks it against the joints' rated torques.
"""

from __future__ import annotations

from collections.abc import Mapping

import mujoco
import numpy as np

from cosim.robots.scene import RobotScene, shift_wrench
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.joint_trajectory import JointTrajectory


def required_torques(scene: RobotScene, trajectory: JointTrajectory, wrenches: Mapping[ArmRole, np.ndarray]) -> np.ndarray:
    """(T, n) N m: the drive torques for every sample and column of ``trajectory`` (joints of ``scene``'s arms).

    wrenches: per arm, (T, 6): the liquid's force (N) and torque (N m) on its vessel at each sample, about the
    vessel's centre of mass (``VesselSpec.com_local``), world frame, as the fluid solver reports it. Computed on a
    private ``MjData``; joints not in the trajectory at 0.
    """
    model = scene.model
    data = mujoco.MjData(model)
    joints = [model.joint(name) for name in trajectory.joint_names]
    qpos = np.array([int(j.qposadr[0]) for j in joints])
    dofs = np.array([int(j.dofadr[0]) for j in joints])
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    out = np.empty(trajectory.positions.shape)
    for i in range(len(trajectory.time)):
        data.qpos[qpos] = trajectory.positions[i]
        data.qvel[dofs] = trajectory.velocities[i]
        data.qacc[dofs] = trajectory.accelerations[i]
        mujoco.mj_inverse(model, data)
        tau = data.qfrc_inverse.copy()
        for role, wrench in wrenches.items():
            body = scene.arms[role].vessel_body
            spec_com = data.xpos[body] + data.xmat[body].reshape(3, 3) @ scene.arms[role].vessel.com_local
            force = wrench[i, :3]
            torque = shift_wrench(force, wrench[i, 3:], spec_com, data.xipos[body])
            mujoco.mj_jac(model, data, jacp, jacr, data.xipos[body], body)
            tau -= jacp.T @ force + jacr.T @ torque
        out[i] = tau[dofs]
    return out
