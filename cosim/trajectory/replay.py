"""Replay a joint trajectory through the arms' position servos in MuJoCo, without liquid, and measure tracking.

The scene is loaded with the liquid as a rigid payload (:mod:`cosim.robots.payload`, default: the pourer full to the
rim, the catcher holding that volume). The arms start exactly on the trajectory's first sample; arms without
columns in the trajectory hold their home posture. Each 2 ms step commands the servos with the trajectory's
position and velocity at the current time (quintic Hermite interpolation of the samples, see
:mod:`cosim.trajectory.interpolation`), then steps the simulation.

Errors, sampled at every step (world frame, SI units):
* joint tracking error ``q_cmd(t) - q(t)`` per joint, rad: maximum of the absolute value and RMS;
* vessel-lip path error: ``|p_lip(FK(q_cmd(t))) - p_lip(t)|`` for the pourer's lip, m: the lip commanded by forward
  kinematics of the trajectory against the lip actually reached; maximum and RMS. The same for the catcher's lip;
* contacts: any contact in the simulation is a collision (the scene excludes the vessel mounts), the first is kept;
* peak actuator torque as a fraction of each joint's torque limit (1.0 = saturated).

Verdict (:meth:`ReplayReport.failures`): the replay passes a tolerance (m) when every vessel's lip stays within it
of its commanded path (largest lip path error, with the time it occurs) and nothing collides;
:data:`DEFAULT_TOLERANCE_M` is 2 mm, about the shift of the stream's landing point such an error causes, small
against the catcher's opening.

What the lip path error is. The payload is rigid and the servos' gravity compensation knows it exactly, so at rest
the lip is where commanded: the error is the servos' dynamic lag behind the commanded motion. A PD servo without
inertia feedforward needs a position error of about ``M qdd / Kp`` to accelerate the arm, so the error follows the
commanded acceleration: the verdict says whether the trajectory's accelerations are ones the servos track within
the tolerance. With ``DYNAMICS`` feedforward (the servo knows the motion's inertia torques, as a real arm's
model-based controller does; ``cosim replay``'s default) that lag is removed and what remains is the servos' response
to what the feedforward misses: the commanded motion between samples (interpolated) and the servos' own transients.

Feedforward (:class:`Feedforward`): gravity compensation is part of the model (the servos always get it, computed
from the model including the rigid payload, as a UR controller does from its configured payload). ``DYNAMICS`` adds
the inverse-dynamics torque ``M(q_d) qdd_d + c(q_d, qd_d)`` of the commanded motion
(:meth:`cosim.robots.scene.RobotScene.dynamics_feedforward`), i.e. computed-torque feedforward.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from cosim.errors import InputError, SimulationError
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.checks import LIMIT_RTOL, POSITION_TOLERANCE
from cosim.trajectory.feedforward import DEFAULT_TOLERANCE_M, Feedforward
from cosim.trajectory.interpolation import QuinticInterpolator
from cosim.trajectory.joint_trajectory import JointTrajectory


@dataclass(frozen=True)
class ContactEvent:
    """A contact seen during the replay: time s, geom and body names, penetration distance m (negative)."""

    time: float
    geom1: str
    geom2: str
    body1: str
    body2: str
    distance: float


@dataclass(frozen=True)
class ReplayReport:
    """Tracking results of one replay (see the module docstring for definitions).

    joint_names: (J,) the trajectory's joints. joint_max_error, joint_rms_error: (J,) rad.
    lip_max_error, lip_rms_error: m, per vessel name; lip_max_time: s, per vessel, when its largest error occurred.
    peak_torque_fraction: (J,), |tau| / limit.
    duration: s simulated. steps: simulation steps. timestep: s.
    first_contact: the first contact, or None. contact_steps: steps with at least one contact.
    """

    joint_names: tuple[str, ...]
    joint_max_error: np.ndarray
    joint_rms_error: np.ndarray
    lip_max_error: dict[str, float]
    lip_rms_error: dict[str, float]
    peak_torque_fraction: np.ndarray
    duration: float
    steps: int
    timestep: float
    first_contact: ContactEvent | None
    contact_steps: int
    lip_max_time: dict[str, float] = field(default_factory=dict)
    pour_vessel: str = field(default="pourer")

    @property
    def max_error_m(self) -> float:
        """Largest pour-lip position error, m."""
        return self.lip_max_error[self.pour_vessel]

    def failures(self, tolerance: float) -> list[str]:
        """Why the replay fails at ``tolerance`` (m): one line per vessel lip whose largest path error exceeds it and
        one for a contact; empty when it passes."""
        lines = [
            f"{vessel} lip path error {error * 1000:.3f} mm (at t={self.lip_max_time.get(vessel, math.nan):.3f} s) above {tolerance * 1000:.3f} mm"
            for vessel, error in self.lip_max_error.items()
            if error > tolerance
        ]
        if self.first_contact is not None:
            c = self.first_contact
            lines.append(f"contact at t={c.time:.3f} s: {c.geom1} ({c.body1}) - {c.geom2} ({c.body2})")
        return lines

    def to_json(self) -> dict:
        """JSON-ready dict: ``max_error_m`` (largest pour-lip error, m), per-joint maxima (rad), the rest."""
        contact = None
        if self.first_contact is not None:
            c = self.first_contact
            contact = {"time_s": c.time, "geom1": c.geom1, "geom2": c.geom2, "body1": c.body1, "body2": c.body2,
                       "distance_m": c.distance}
        return {
            "max_error_m": self.max_error_m,
            "rms_error_m": self.lip_rms_error[self.pour_vessel],
            "joint_max_error_rad": dict(zip(self.joint_names, map(float, self.joint_max_error))),
            "joint_rms_error_rad": dict(zip(self.joint_names, map(float, self.joint_rms_error))),
            "lip_max_error_m": dict(self.lip_max_error),
            "lip_rms_error_m": dict(self.lip_rms_error),
            "lip_max_time_s": dict(self.lip_max_time),
            "peak_torque_fraction": dict(zip(self.joint_names, map(float, self.peak_torque_fraction))),
            "duration_s": self.duration,
            "steps": self.steps,
            "timestep_s": self.timestep,
            "contact_steps": self.contact_steps,
            "first_contact": contact,
        }


def _arm_columns(scene: RobotScene, trajectory: JointTrajectory) -> dict[ArmRole, list[int]]:
    known = {name for arm in scene.arms.values() for name in arm.joints}
    unknown = [n for n in trajectory.joint_names if n not in known]
    if unknown:
        raise InputError(f"trajectory: unknown joint(s) {', '.join(unknown)} (the scene has {', '.join(sorted(known))})")
    columns = {}
    for role, arm in scene.arms.items():
        present = [n for n in arm.joints if n in trajectory.joint_names]
        if present and len(present) != len(arm.joints):
            missing = [n for n in arm.joints if n not in trajectory.joint_names]
            raise InputError(f"trajectory: {role.value} is missing joint(s) {', '.join(missing)}")
        if present:
            columns[role] = trajectory.columns(arm.joints)
    return columns


def _check_within_limits(scene: RobotScene, trajectory: JointTrajectory) -> None:
    """Refuse a trajectory the arms cannot run: a sample's position outside its joint's range, or its speed over the
    arm's joint speed limit (where the scene gives them). MuJoCo would otherwise be driven there and report the
    blow-up as a failed replay."""
    model = scene.model
    speed_limit = {name: float(limit) for arm in scene.arms.values() for name, limit in zip(arm.joints, arm.max_joint_speed)}
    for j, name in enumerate(trajectory.joint_names):
        jid = model.joint(name).id
        positions, speeds = trajectory.positions[:, j], np.abs(trajectory.velocities[:, j])
        if model.jnt_limited[jid]:
            lo, hi = (float(v) for v in model.jnt_range[jid])
            outside = np.flatnonzero((positions < lo - POSITION_TOLERANCE) | (positions > hi + POSITION_TOLERANCE))
            if outside.size:
                k = int(outside[0])
                raise InputError(f"trajectory: {name}.pos: must be in [{lo:.6g}, {hi:.6g}] rad (the joint's range), got "
                                 f"{positions[k]:.6g} at t = {trajectory.time[k]:.6g} s")
        limit = speed_limit.get(name, math.inf)
        over = np.flatnonzero(speeds > limit * (1.0 + LIMIT_RTOL))
        if over.size:
            k = int(over[0])
            raise InputError(f"trajectory: {name}.vel: must be within +-{limit:.6g} rad/s (the arm's joint speed limit), "
                             f"got {trajectory.velocities[k, j]:.6g} at t = {trajectory.time[k]:.6g} s")


def _torque_limits(model: mujoco.MjModel, trajectory: JointTrajectory) -> tuple[np.ndarray, np.ndarray]:
    """(dof indices (J,), torque limit (J,) N m) of the trajectory's joints; inf where the joint is not clamped."""
    dofs, limits = [], []
    for name in trajectory.joint_names:
        jid = model.joint(name).id
        dofs.append(model.jnt_dofadr[jid])
        limited = bool(model.jnt_actfrclimited[jid])
        limits.append(max(abs(model.jnt_actfrcrange[jid, 0]), abs(model.jnt_actfrcrange[jid, 1])) if limited else math.inf)
    return np.array(dofs), np.array(limits)


def replay(scene: RobotScene, trajectory: JointTrajectory, feedforward: Feedforward = Feedforward.GRAVITY) -> ReplayReport:
    """Play ``trajectory`` on ``scene`` (its live data is reset to home first) and measure the tracking."""
    columns = _arm_columns(scene, trajectory)
    _check_within_limits(scene, trajectory)
    model, data = scene.model, scene.data
    scene.reset_home()
    command = QuinticInterpolator(trajectory)
    q0, qd0, _ = command(trajectory.time[0])
    for role, cols in columns.items():
        scene.set_joint_positions(role, q0[cols], qd0[cols])
    mujoco.mj_forward(model, data)

    fk = mujoco.MjData(model)  # private data: forward kinematics of the commanded configuration
    fk.qpos[:] = data.qpos
    # private data: kinematics of the actual configuration (after mj_step, data.site_xpos still belongs to the
    # configuration before the step's integration)
    measured = mujoco.MjData(model)
    vessels = {arm.vessel.name: arm for arm in scene.arms.values()}
    dofs, limits = _torque_limits(model, trajectory)
    qpos_cols = np.concatenate([scene.arms[role].qpos_adr for role in columns])
    traj_cols = np.concatenate([np.array(cols) for cols in columns.values()])

    dt = model.opt.timestep
    steps = int(math.ceil(trajectory.duration / dt - 1e-9)) + 1
    sq_joint = np.zeros(len(trajectory.joint_names))
    max_joint = np.zeros_like(sq_joint)
    lip_sq = {name: 0.0 for name in vessels}
    lip_max = {name: 0.0 for name in vessels}
    lip_max_time = {name: trajectory.time[0] for name in vessels}
    peak_torque = np.zeros_like(sq_joint)
    first_contact, contact_steps = None, 0
    for k in range(steps):
        t = trajectory.time[0] + k * dt
        q_cmd, qd_cmd, qdd_cmd = command(t)
        # measure the state at time t against the command at time t
        err = q_cmd[traj_cols] - data.qpos[qpos_cols]
        joint_err = np.zeros_like(sq_joint)
        joint_err[traj_cols] = err
        sq_joint += joint_err**2
        max_joint = np.maximum(max_joint, np.abs(joint_err))
        fk.qpos[qpos_cols] = q_cmd[traj_cols]
        mujoco.mj_kinematics(model, fk)
        measured.qpos[:] = data.qpos
        mujoco.mj_kinematics(model, measured)
        for name, arm in vessels.items():
            e = float(np.linalg.norm(fk.site_xpos[arm.lip_site] - measured.site_xpos[arm.lip_site]))
            lip_sq[name] += e * e
            if e > lip_max[name]:
                lip_max[name], lip_max_time[name] = e, t
        if data.ncon > 0:
            contact_steps += 1
            if first_contact is None:
                c = data.contact[0]
                first_contact = ContactEvent(
                    t, model.geom(c.geom1).name, model.geom(c.geom2).name, model.body(model.geom_bodyid[c.geom1]).name,
                    model.body(model.geom_bodyid[c.geom2]).name, float(c.dist),
                )
        peak_torque = np.maximum(peak_torque, np.abs(data.qfrc_actuator[dofs]) / limits)
        if k == steps - 1:
            break
        for role, cols in columns.items():
            tau = None
            if feedforward is Feedforward.DYNAMICS:
                tau = scene.dynamics_feedforward(role, q_cmd[cols], qd_cmd[cols], qdd_cmd[cols])
            scene.set_joint_targets(role, q_cmd[cols], qd_cmd[cols], tau)
        mujoco.mj_step(model, data)
        if not np.all(np.isfinite(data.qpos)):
            raise SimulationError(f"replay diverged at t={t:.3f} s (non-finite joint positions)")
    return ReplayReport(
        joint_names=trajectory.joint_names,
        joint_max_error=max_joint,
        joint_rms_error=np.sqrt(sq_joint / steps),
        lip_max_error=lip_max,
        lip_rms_error={name: math.sqrt(v / steps) for name, v in lip_sq.items()},
        peak_torque_fraction=peak_torque,
        duration=(steps - 1) * dt,
        steps=steps,
        timestep=dt,
        first_contact=first_contact,
        contact_steps=contact_steps,
        lip_max_time=lip_max_time,
        pour_vessel=scene.arms[ArmRole.POUR].vessel.name,
    )
