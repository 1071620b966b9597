"""How the liquid loads the arms of a coupled run: the vessel deviation it causes and the drives' torques.

Deviation caused by the liquid. A twin of the arms (a second ``MjData`` of the same model, same start) gets every
step the same servo commands (desired ``q``, ``qd``) as the live arms, without the liquid's wrench and without its
compensation, and is stepped alike: it is where the commanded motion puts the vessels when no liquid acts (the
servos' own tracking of the arm's inertia included). Each step the live vessel's pose is compared with the twin's:
position ``|p - p_twin|`` (m) and rotation angle ``2 atan2(|v|, |w|)`` of ``q_twin^-1 q`` (rad). In a one-way run the
two are the same data, bit for bit; with ideal force-torque compensation they differ by round-off.

Servo torques: the largest ``|qfrc_actuator|`` of each arm joint (servo plus gravity compensation, as the drive
delivers it; clamped by the model at its actuator force range, the rated torque).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import mujoco
import numpy as np

from cosim.coupling.exchange import ROLES
from cosim.frames import vector_norm
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole


def rotation_angle(quat_a: np.ndarray, quat_b: np.ndarray, scratch: np.ndarray | None = None) -> float:
    """rad, the angle of the rotation taking orientation ``quat_a`` to ``quat_b`` (unit quaternions [w, x, y, z]);
    ``scratch``: (2, 4) floats to work in (None: new ones)."""
    inverse, relative = np.empty((2, 4)) if scratch is None else scratch
    mujoco.mju_negQuat(inverse, quat_a)
    mujoco.mju_mulQuat(relative, inverse, quat_b)
    return 2.0 * math.atan2(float(vector_norm(relative[1:])), abs(float(relative[0])))


class ArmLoadMonitor:
    """Tracks, over a coupled run of ``scene``, each vessel's largest deviation caused by the liquid and each arm
    joint's largest drive torque. Make it before the first step; call :meth:`step` after each live ``mj_step`` with
    the servo targets of that step."""

    def __init__(self, scene: RobotScene) -> None:
        self.scene = scene
        self.twin = mujoco.MjData(scene.model)
        mujoco.mj_copyData(self.twin, scene.model, scene.data)
        self.max_position = {role: 0.0 for role in ROLES}  # m
        self.max_rotation = {role: 0.0 for role in ROLES}  # rad
        self.peak_torque = {role: np.zeros(len(scene.arms[role].joints)) for role in ROLES}  # N m
        self._quaternions = np.empty((2, 4))  # rotation_angle's scratch

    def step(self, targets: Mapping[ArmRole, tuple[np.ndarray, np.ndarray | None]]) -> None:
        """Step the twin with ``targets`` (per arm: desired q (n,) rad, qd (n,) rad/s) and update the maxima."""
        scene, twin, live = self.scene, self.twin, self.scene.data
        for role in ROLES:
            q, qd = targets[role]
            twin.ctrl[scene.arms[role].ctrl_adr] = scene.servo_controls(role, q, qd)
        mujoco.mj_step(scene.model, twin)
        for role in ROLES:
            arm = scene.arms[role]
            body = arm.vessel_body
            self.max_position[role] = max(self.max_position[role], float(vector_norm(live.xpos[body] - twin.xpos[body])))
            self.max_rotation[role] = max(self.max_rotation[role], rotation_angle(twin.xquat[body], live.xquat[body], self._quaternions))
            peak = self.peak_torque[role]
            np.maximum(peak, np.abs(live.qfrc_actuator[arm.dof_adr]), out=peak)
