"""How the liquid loads the arms of a coupled run: the vessel deviation it causes and the drives' torques.

Deviation caused by the liquid. A twin of the arms (a second ``MjData`` of the same model, same start) gets every
step the same servo commands (desired ``q``, ``qd``) as the live arms, without the liquid's wrench and without its
compensation, and is stepped alike: it is where the commanded motion puts the vessels when no liquid acts (the
servos' own tracking of the arm's inertia included). Each step's live vessel pose is compared with the twin's:
position ``|p - p_twin|`` (m) and rotation angle ``2 atan2(|v|, |w|)`` of ``q_twin^-1 q`` (rad). In a one-way run the
two are the same data, bit for bit; with ideal force-torque compensation they differ by round-off.

Servo torques: the largest ``|qfrc_actuator|`` of each arm joint (servo plus gravity compensation, as the drive
delivers it; clamped by the model at its actuator force range, the rated torque).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

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


def rotation_angles(quat_a: np.ndarray, quat_b: np.ndarray) -> np.ndarray:
    """rad (m,), :func:`rotation_angle` of each row of ``quat_a`` and ``quat_b`` (m, 4) at once: the relative
    quaternion ``q_a^-1 q_b`` has ``w = a_w b_w + a_v . b_v`` and ``v = a_w b_v - b_w a_v - a_v x b_v``. Within a few
    1e-16 rad of :func:`rotation_angle` (its rounding differs)."""
    a_w, a_v, b_w, b_v = quat_a[:, :1], quat_a[:, 1:], quat_b[:, :1], quat_b[:, 1:]
    w = a_w[:, 0] * b_w[:, 0] + np.einsum("ij,ij->i", a_v, b_v)
    v = a_w * b_v - b_w * a_v - np.cross(a_v, b_v)
    return 2.0 * np.arctan2(np.linalg.norm(v, axis=1), np.abs(w))


def largest(approximate: np.ndarray, exact: Callable[[int], float]) -> float:
    """The largest ``exact(s)`` over the indices ``s`` of ``approximate`` (>= 0), whose entries are within
    :data:`SCREEN_TOLERANCE` of them: ``exact`` is evaluated only where ``approximate`` comes that near its largest
    entry, which holds the largest exact value, so the result is exact. NaN entries are passed over (as a running
    ``max`` from 0 passes over NaN values); 0 when all are NaN."""
    valid = approximate[~np.isnan(approximate)]
    if not valid.size:
        return 0.0
    top = float(valid.max())
    near = np.flatnonzero(approximate >= top - SCREEN_TOLERANCE * (1.0 + top)) if math.isfinite(top) else np.flatnonzero(approximate == top)
    return max(exact(int(s)) for s in near)


# The vectorised deviations differ from the exact ones by round-off (about 1e-16 relative, or rad, for a deviation
# below 1); a screen far wider than that, far narrower than the deviations' change from step to step.
SCREEN_TOLERANCE = 1e-9
BATCH_STEPS = 250  # MuJoCo steps recorded before their maxima are taken (a few hundred kB of records)


class ArmLoadMonitor:
    """Tracks, over a coupled run of ``scene``, each vessel's largest deviation caused by the liquid and each arm
    joint's largest drive torque. Make it before the first step; call :meth:`step` after each live ``mj_step`` with
    the servo targets of that step.

    Each step records the vessels' poses (live and twin) and the drives' torques; the maxima are taken over a batch
    of :data:`BATCH_STEPS` records at once (numpy over the batch instead of a dozen small calls per step) and when
    read. The deviations are screened vectorised and the largest evaluated exactly (:func:`largest`): the same values,
    to the bit, as taken step by step. The twin's frames of a step are recorded from its next ``mj_step``, whose
    forward pass computes them at the same positions before it integrates (the same bits as an ``mj_kinematics``
    after the step, which would change nothing the twin's next step computes); the last step's are computed when
    the maxima are read."""

    def __init__(self, scene: RobotScene) -> None:
        self.scene = scene
        self.twin = mujoco.MjData(scene.model)
        mujoco.mj_copyData(self.twin, scene.model, scene.data)
        arms = [scene.arms[role] for role in ROLES]
        self._bodies = np.array([arm.vessel_body for arm in arms])
        self._dofs = np.concatenate([arm.dof_adr for arm in arms])
        # both arms' servo law at once (RobotScene.servo_controls, u = q + kv qd / kp, entry by entry)
        self._ctrl_adr = np.concatenate([arm.ctrl_adr for arm in arms])
        self._kv, self._kp = np.concatenate([arm.kv for arm in arms]), np.concatenate([arm.kp for arm in arms])
        self._joint_ranges = np.cumsum([0] + [len(arm.joints) for arm in arms])
        self._live_pos, self._twin_pos = np.empty((BATCH_STEPS, len(ROLES), 3)), np.empty((BATCH_STEPS, len(ROLES), 3))
        self._live_quat, self._twin_quat = np.empty((BATCH_STEPS, len(ROLES), 4)), np.empty((BATCH_STEPS, len(ROLES), 4))
        self._torques = np.empty((BATCH_STEPS, len(self._dofs)))
        self._recorded = 0  # records in the batch
        self._twin_pending = False  # the last record still lacks the twin's frames
        self._max_position = np.zeros(len(ROLES))  # m
        self._max_rotation = np.zeros(len(ROLES))  # rad
        self._peak_torque = np.zeros(len(self._dofs))  # N m
        self._quaternions = np.empty((2, 4))  # rotation_angle's scratch

    def step(self, targets: Mapping[ArmRole, tuple[np.ndarray, np.ndarray]]) -> None:
        """Step the twin with ``targets`` (per arm: desired q (n,) rad, qd (n,) rad/s) and record the step."""
        scene, twin, live = self.scene, self.twin, self.scene.data
        q = np.concatenate([targets[role][0] for role in ROLES])
        qd = np.concatenate([targets[role][1] for role in ROLES])
        twin.ctrl[self._ctrl_adr] = q + self._kv * qd / self._kp
        mujoco.mj_step(scene.model, twin)  # its forward pass leaves the frames of the previous step's end
        if self._twin_pending:
            self._record_twin()
        if self._recorded == BATCH_STEPS:
            self._take_maxima()
        k, bodies = self._recorded, self._bodies
        live.xpos.take(bodies, axis=0, out=self._live_pos[k])  # the coupled step brought the live frames to the new qpos
        live.xquat.take(bodies, axis=0, out=self._live_quat[k])
        live.qfrc_actuator.take(self._dofs, out=self._torques[k])
        self._recorded += 1
        self._twin_pending = True

    def _record_twin(self) -> None:
        """The twin's frames, as they are, into the last record."""
        k, twin = self._recorded - 1, self.twin
        twin.xpos.take(self._bodies, axis=0, out=self._twin_pos[k])
        twin.xquat.take(self._bodies, axis=0, out=self._twin_quat[k])
        self._twin_pending = False

    def _take_maxima(self) -> None:
        """The batch's records into the maxima (the last step's twin frames computed at its positions); the batch
        starts again."""
        if self._twin_pending:
            mujoco.mj_kinematics(self.scene.model, self.twin)
            self._record_twin()
        n = self._recorded
        if n == 0:
            return
        offset = self._live_pos[:n] - self._twin_pos[:n]  # (n, arms, 3) m, each step's as the step computed it
        for a in range(len(ROLES)):
            twin_quat, live_quat = self._twin_quat[:n, a], self._live_quat[:n, a]
            position = largest(np.linalg.norm(offset[:, a], axis=1), lambda s: float(vector_norm(offset[s, a])))
            rotation = largest(rotation_angles(twin_quat, live_quat), lambda s: rotation_angle(twin_quat[s], live_quat[s], self._quaternions))
            self._max_position[a] = max(self._max_position[a], position)
            self._max_rotation[a] = max(self._max_rotation[a], rotation)
        np.maximum(self._peak_torque, np.abs(self._torques[:n]).max(axis=0), out=self._peak_torque)
        self._recorded = 0

    @property
    def max_position(self) -> dict[ArmRole, float]:
        """m, per arm: the largest distance between the live vessel's frame and the twin's so far."""
        self._take_maxima()
        return {role: float(self._max_position[a]) for a, role in enumerate(ROLES)}

    @property
    def max_rotation(self) -> dict[ArmRole, float]:
        """rad, per arm: the largest rotation between the live vessel's frame and the twin's so far."""
        self._take_maxima()
        return {role: float(self._max_rotation[a]) for a, role in enumerate(ROLES)}

    @property
    def peak_torque(self) -> dict[ArmRole, np.ndarray]:
        """N m, per arm: each joint's largest ``|qfrc_actuator|`` so far (n,)."""
        self._take_maxima()
        lo, hi = self._joint_ranges[:-1], self._joint_ranges[1:]
        return {role: self._peak_torque[lo[a]:hi[a]].copy() for a, role in enumerate(ROLES)}
