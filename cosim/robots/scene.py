"""The live robot scene: load it, read vessel states, apply wrenches, command the arms, solve vessel targets.

Conventions (see :mod:`cosim.robots`): world z up, SI units, quaternions [w, x, y, z]; pour plane x-z at y = 0.
Vessel body frame == VesselSpec local frame (origin at the centre of the inner floor, +x toward the lip, +z up).
``data.xfrc_applied`` of a vessel body is a world-frame wrench at the body's centre of mass (``data.xipos``).

A scene file written by :mod:`cosim.robots.scene_builder` records its mapping in custom fields
(``cosim/<role>/joints``, ``.../driver_joints``, ``.../vessel``, ``.../flange_link``, ``.../max_joint_speed``) and has a
``home`` keyframe, so :class:`RobotScene` loads the default scene and any user scene the builder wrote the same way (a
scene without ``driver_joints`` exports the arm's MJCF joint names).

Servo law. Each arm joint has a position servo ``tau = kp (u - q) - kv qdot`` (MuJoCo ``position`` actuator), plus
the model's gravity compensation routed through the actuators (body ``gravcomp``, joint ``actuatorgravcomp``), the
sum clamped to the joint torque limit. :meth:`RobotScene.set_joint_targets` commands
``u = q_d + (kv qd_d + tau_ff) / kp``, which makes the servo force exactly
``kp (q_d - q) + kv (qd_d - qdot) + tau_ff``: PD tracking of the desired position and velocity with an optional
feedforward torque (e.g. ``-J^T w`` for a known external wrench).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import unquote

import mujoco
import numpy as np

from cosim.errors import InputError
from cosim.robots import assets
from cosim.robots.ik import ArmIK, IKSettings
from cosim.robots.payload import PayloadMode, add_liquid_payload, payload_fill_depths
from cosim.robots.planar import PlanarPose, planar_to_world
from cosim.robots.scene_builder import CUSTOM_PREFIX, HOME_KEY, build_scene_spec
from cosim.robots.scene_config import ArmRole, SceneConfig
from cosim.robots.vessel_mjcf import frame_site, lip_site
from cosim.frames import cross3
from cosim.mesh_vessel import load_vessel_mesh
from cosim.vessel import VesselShape, VesselSpec, mesh_vessel_spec


@dataclass(frozen=True)
class VesselState:
    """A vessel's state, world frame.

    pos: (3,) m, vessel frame origin (centre of the inner floor). quat: (4,) [w, x, y, z], vessel frame orientation.
    lin_vel: (3,) m/s, velocity of the vessel frame origin. ang_vel: (3,) rad/s, angular velocity.
    com: (3,) m, centre of mass of the vessel body (the point ``xfrc_applied`` acts at).
    """

    pos: np.ndarray
    quat: np.ndarray
    lin_vel: np.ndarray
    ang_vel: np.ndarray
    com: np.ndarray

    def velocity_at(self, point: np.ndarray) -> np.ndarray:
        """Velocity (3,) m/s of the rigid vessel at world ``point`` (3,) m: ``v + w x (p - pos)``."""
        return self.lin_vel + cross3(self.ang_vel, np.asarray(point, dtype=float) - self.pos)


@dataclass(frozen=True)
class ArmInfo:
    """Index data of one arm in a compiled scene (arrays are per arm joint, base to tip, length n)."""

    role: ArmRole
    joints: tuple[str, ...]  # full joint names, e.g. "pour_arm/shoulder_pan"
    driver_joints: tuple[str, ...]  # the same joints as the arm's ROS 2 driver names them, e.g. "shoulder_pan_joint"
    qpos_adr: np.ndarray
    dof_adr: np.ndarray
    ctrl_adr: np.ndarray
    kp: np.ndarray  # N m/rad
    kv: np.ndarray  # N m s/rad
    max_joint_speed: np.ndarray  # rad/s
    vessel: VesselSpec
    vessel_body: int
    frame_site: int
    lip_site: int
    flange_body: int
    home_q: np.ndarray  # rad
    home_pos: np.ndarray  # (3,) m, vessel frame origin at home
    home_quat: np.ndarray  # (4,), vessel orientation at home


def shift_wrench(force: np.ndarray, torque: np.ndarray, from_point: np.ndarray, to_point: np.ndarray) -> np.ndarray:
    """Torque (3,) N m about ``to_point`` of a wrench given as ``force`` (3,) N and ``torque`` (3,) N m about
    ``from_point``; all world frame: ``tau_to = tau_from + (from_point - to_point) x force``. Use it to move a wrench
    to the vessel's centre of mass (``VesselState.com``) before :meth:`RobotScene.apply_vessel_wrench`."""
    return np.asarray(torque, dtype=float) + cross3(np.asarray(from_point, dtype=float) - np.asarray(to_point, dtype=float), force)


def _text(model: mujoco.MjModel, name: str, source: str) -> str:
    tid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, name)
    if tid < 0:
        raise InputError(f"{source}: missing custom text {name!r} (not a scene written by cosim.robots.scene_builder)")
    adr, size = model.text_adr[tid], model.text_size[tid]
    return bytes(model.text_data[adr : adr + size - 1]).decode()


def _numeric(model: mujoco.MjModel, name: str, source: str) -> np.ndarray:
    nid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
    if nid < 0:
        raise InputError(f"{source}: missing custom numeric {name!r}")
    adr, size = model.numeric_adr[nid], model.numeric_size[nid]
    return model.numeric_data[adr : adr + size].copy()


def _parse_vessel(record: str, source: str) -> VesselSpec:
    fields = dict(item.split("=", 1) for item in record.split())
    try:
        if fields["shape"] == VesselShape.MESH.value:
            mesh = load_vessel_mesh(unquote(fields["mesh"]), float(fields["pour_direction"]), f"{source}: vessel {fields['name']} mesh")
            return mesh_vessel_spec(fields["name"], mesh, float(fields["wall_density"]))
        return VesselSpec(
            name=fields["name"],
            shape=VesselShape(fields["shape"]),
            inner_width=float(fields["inner_width"]),
            inner_depth=float(fields["inner_depth"]),
            inner_height=float(fields["inner_height"]),
            wall_thickness=float(fields["wall_thickness"]),
            wall_density=float(fields["wall_density"]),
        )
    except (KeyError, ValueError) as exc:
        raise InputError(f"{source}: bad vessel record {record!r} ({exc})") from None


def _servo(model: mujoco.MjModel, joint_id: int, joint: str, source: str) -> tuple[int, float, float]:
    """(ctrl address, kp, kv) of the position servo driving ``joint_id``."""
    for act in range(model.nu):
        if model.actuator_trntype[act] == mujoco.mjtTrn.mjTRN_JOINT and model.actuator_trnid[act, 0] == joint_id:
            kp, bias = model.actuator_gainprm[act, 0], model.actuator_biasprm[act]
            is_servo = (
                model.actuator_gaintype[act] == mujoco.mjtGain.mjGAIN_FIXED
                and model.actuator_biastype[act] == mujoco.mjtBias.mjBIAS_AFFINE
                and kp > 0.0
                and math.isclose(bias[1], -kp, rel_tol=1e-9)
                and model.actuator_ctrlnum[act] == 1
            )
            if not is_servo:
                raise InputError(f"{source}: the actuator on joint {joint!r} is not a position servo (kp, kv)")
            return int(model.actuator_ctrladr[act]), float(kp), float(-bias[2])
    raise InputError(f"{source}: joint {joint!r} has no actuator")


def _arm_info(model: mujoco.MjModel, home: mujoco.MjData, role: ArmRole, source: str) -> ArmInfo:
    base = f"{CUSTOM_PREFIX}/{role.value}"
    joints = tuple(_text(model, f"{base}/joints", source).split())
    has_driver_names = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, f"{base}/driver_joints") >= 0
    prefix = f"{role.value}/"
    driver_joints = (tuple(_text(model, f"{base}/driver_joints", source).split()) if has_driver_names
                     else tuple(j.removeprefix(prefix) for j in joints))
    if len(driver_joints) != len(joints):
        raise InputError(f"{source}: {base}/driver_joints names {len(driver_joints)} joints, the arm has {len(joints)}")
    vessel = _parse_vessel(_text(model, f"{base}/vessel", source), source)
    qpos_adr, dof_adr, ctrl_adr, kp, kv = [], [], [], [], []
    for joint in joints:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        if jid < 0:
            raise InputError(f"{source}: joint {joint!r} of {role.value} not found")
        qpos_adr.append(model.jnt_qposadr[jid])
        dof_adr.append(model.jnt_dofadr[jid])
        adr, p, v = _servo(model, jid, joint, source)
        ctrl_adr.append(adr)
        kp.append(p)
        kv.append(v)
    speeds = _numeric(model, f"{base}/max_joint_speed", source)
    if speeds.size != len(joints):
        raise InputError(f"{source}: {base}/max_joint_speed has {speeds.size} values for {len(joints)} joints")
    vessel_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, vessel.name)
    flange_body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, _text(model, f"{base}/flange_link", source))
    fsite = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, frame_site(vessel))
    lsite = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, lip_site(vessel))
    if min(vessel_body, flange_body, fsite, lsite) < 0:
        raise InputError(f"{source}: vessel {vessel.name!r} bodies/sites missing")
    qpos_adr_arr = np.array(qpos_adr)
    return ArmInfo(
        role=role,
        joints=joints,
        driver_joints=driver_joints,
        qpos_adr=qpos_adr_arr,
        dof_adr=np.array(dof_adr),
        ctrl_adr=np.array(ctrl_adr),
        kp=np.array(kp),
        kv=np.array(kv),
        max_joint_speed=speeds,
        vessel=vessel,
        vessel_body=vessel_body,
        frame_site=fsite,
        lip_site=lsite,
        flange_body=flange_body,
        home_q=home.qpos[qpos_adr_arr].copy(),
        home_pos=home.site_xpos[fsite].copy(),
        home_quat=home.xquat[vessel_body].copy(),
    )


def _load_spec(path: Path) -> mujoco.MjSpec:
    if path.is_dir():
        raise InputError(f"scene {path}: a folder, not a scene file")
    if not path.is_file():
        raise InputError(f"scene {path}: file not found")
    try:
        return mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:
        raise InputError(f"scene {path}: not a loadable MJCF: {str(exc).splitlines()[0]}") from None


class RobotScene:
    """A compiled two-arm scene with its live ``MjData`` (``self.model``, ``self.data``) and its ``MjSpec``.

    Build with :meth:`load` (a scene file: the default ``models/scene.xml`` or one written by the scene builder),
    :meth:`from_config` (a :class:`SceneConfig`, e.g. with a user's arm) or :meth:`from_spec`. The data starts at the
    ``home`` keyframe.
    """

    def __init__(self, model: mujoco.MjModel, source: str = "scene", spec: mujoco.MjSpec | None = None) -> None:
        self.model = model
        self.spec = spec  # the spec the model was compiled from, when known (see cosim.robots.collision)
        self.data = mujoco.MjData(model)
        key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, HOME_KEY)
        if key < 0:
            raise InputError(f"{source}: no {HOME_KEY!r} keyframe")
        self.home_key = key
        self.reset_home()
        self.arms = {role: _arm_info(model, self.data, role, source) for role in ArmRole}
        self._ik: dict[ArmRole, ArmIK] = {}
        self._inverse_data: mujoco.MjData | None = None
        self._jacobian_data: mujoco.MjData | None = None
        self._jacobians: tuple[np.ndarray, np.ndarray] | None = None  # (3, nv) positional and rotational, reused

    # ---- construction --------------------------------------------------------------------------------------------
    @classmethod
    def from_spec(cls, spec: mujoco.MjSpec, payload: PayloadMode = PayloadMode.EMPTY, source: str = "scene") -> "RobotScene":
        """Compile ``spec`` (after adding the rigid liquid payload for ``payload``) into a scene."""
        if payload is not PayloadMode.EMPTY:
            probe = spec.compile()
            pourer = _parse_vessel(_text(probe, f"{CUSTOM_PREFIX}/{ArmRole.POUR.value}/vessel", source), source)
            catcher = _parse_vessel(_text(probe, f"{CUSTOM_PREFIX}/{ArmRole.CATCH.value}/vessel", source), source)
            depths = payload_fill_depths(pourer, catcher, payload)
            for vessel in (pourer, catcher):
                if depths[vessel.name] > 0.0:
                    add_liquid_payload(spec, vessel, depths[vessel.name])
        return cls(spec.compile(), source, spec)

    @classmethod
    def from_config(cls, config: SceneConfig | None = None, payload: PayloadMode = PayloadMode.EMPTY) -> "RobotScene":
        """Build the scene for ``config`` (e.g. a user's arm MJCF with its mapping; default: the project's scene)."""
        return cls.from_spec(build_scene_spec(config), payload, source="scene config")

    @classmethod
    def load(cls, path: str | Path | None = None, payload: PayloadMode = PayloadMode.EMPTY) -> "RobotScene":
        """Load a scene file (default: the project's ``models/scene.xml``), optionally with a rigid liquid payload."""
        path = Path(path) if path is not None else assets.model_path(assets.DEFAULT_SCENE)
        return cls.from_spec(_load_spec(path), payload, source=f"scene {path}")

    # ---- state ---------------------------------------------------------------------------------------------------
    def reset_home(self) -> None:
        """Put the live data at the home keyframe (positions, zero velocities, servo targets) and run forward."""
        mujoco.mj_resetDataKeyframe(self.model, self.data, self.home_key)
        mujoco.mj_forward(self.model, self.data)

    def posed(self, configuration: Mapping[ArmRole, np.ndarray]) -> mujoco.MjData:
        """A new MjData at the home keyframe with the arms at ``configuration`` (role -> q (n,) rad; arms not named
        stay at home), bodies, geoms and sites placed by forward kinematics (``mj_kinematics``); the live data is
        untouched."""
        data = mujoco.MjData(self.model)
        mujoco.mj_resetDataKeyframe(self.model, data, self.home_key)
        for role, q in configuration.items():
            data.qpos[self.arms[role].qpos_adr] = q
        mujoco.mj_kinematics(self.model, data)
        return data

    def joint_positions(self, role: ArmRole) -> np.ndarray:
        """(n,) rad, the arm's current joint angles."""
        return self.data.qpos[self.arms[role].qpos_adr].copy()

    def joint_velocities(self, role: ArmRole) -> np.ndarray:
        """(n,) rad/s, the arm's current joint velocities."""
        return self.data.qvel[self.arms[role].dof_adr].copy()

    def set_joint_positions(self, role: ArmRole, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        """Teleport the arm to ``q`` (n,) rad with velocity ``qd`` (default 0) and make the servos hold there."""
        arm = self.arms[role]
        self.data.qpos[arm.qpos_adr] = q
        self.data.qvel[arm.dof_adr] = 0.0 if qd is None else qd
        self.set_joint_targets(role, q, qd)

    def set_joint_targets(
        self, role: ArmRole, q: np.ndarray, qd: np.ndarray | None = None, tau_ff: np.ndarray | None = None
    ) -> None:
        """Command the arm's servos to desired joint positions ``q`` (n,) rad and velocities ``qd`` (n,) rad/s, with an
        optional feedforward torque ``tau_ff`` (n,) N m (see the module docstring for the servo law)."""
        self.data.ctrl[self.arms[role].ctrl_adr] = self.servo_controls(role, q, qd, tau_ff)

    def servo_controls(
        self, role: ArmRole, q: np.ndarray, qd: np.ndarray | None = None, tau_ff: np.ndarray | None = None
    ) -> np.ndarray:
        """The arm's servo controls (n,) ``u = q + (kv qd + tau_ff) / kp`` for :meth:`set_joint_targets`' arguments
        (for an ``MjData`` of this model other than the live one)."""
        arm = self.arms[role]
        u = np.asarray(q, dtype=float).copy()
        if qd is not None:
            u += arm.kv * np.asarray(qd, dtype=float) / arm.kp
        if tau_ff is not None:
            u += np.asarray(tau_ff, dtype=float) / arm.kp
        return u

    def dynamics_feedforward(self, role: ArmRole, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """Inverse-dynamics feedforward torque (n,) N m for desired ``q``, ``qd``, ``qdd`` (n,) of the arm.

        ``M(q) qdd + c(q, qd)`` (inertia incl. armature, Coriolis and centrifugal terms) at the desired state, the
        other arm at its current state; gravity is left out because the model's gravity compensation already
        supplies it through the actuators. Computed on a private MjData (``mj_inverse``), the live data is untouched.
        """
        arm, m = self.arms[role], self.model
        if self._inverse_data is None:
            self._inverse_data = mujoco.MjData(m)
        d = self._inverse_data
        d.qpos[:], d.qvel[:] = self.data.qpos, self.data.qvel
        d.qacc[:] = 0.0
        d.qpos[arm.qpos_adr], d.qvel[arm.dof_adr], d.qacc[arm.dof_adr] = q, qd, qdd
        mujoco.mj_inverse(m, d)
        return d.qfrc_inverse[arm.dof_adr] - d.qfrc_gravcomp[arm.dof_adr]

    def wrench_joint_torque(self, role: ArmRole, force: np.ndarray, torque: np.ndarray, kinematics_current: bool = False) -> np.ndarray:
        """Joint torques (n,) N m that a wrench on the vessel exerts on the arm: ``J_p^T force + J_r^T torque``.

        ``force`` (3,) N and ``torque`` (3,) N m act at the vessel's centre of mass, world frame (as
        :meth:`apply_vessel_wrench`); the Jacobians are taken at the current joint positions on a private MjData,
        or, with ``kinematics_current``, on the live data itself, whose caller vouches that its frames are those of
        its current positions (``mj_forward``, or ``mj_kinematics`` and ``mj_comPos`` since the positions last
        changed, as the coupled step loop keeps them): the same values, without computing them again.
        Pass ``tau_ff = -wrench_joint_torque(...)`` to :meth:`set_joint_targets` to feed forward a known external
        wrench (e.g. the liquid's reaction), as a controller that knows its payload would.
        """
        arm, m = self.arms[role], self.model
        if self._jacobian_data is None:
            self._jacobian_data = mujoco.MjData(m)
            self._jacobian_data.qpos[:] = np.nan  # no kinematics computed yet
            self._jacobians = (np.empty((3, m.nv)), np.empty((3, m.nv)))  # mj_jac writes every entry
        d, live = self._jacobian_data, self.data
        if kinematics_current:
            d = live
        # the step loop asks for both arms at one configuration: its kinematics once (compared as bytes: exact, and
        # without array_equal's dispatch)
        elif not (d.qpos.tobytes() == live.qpos.tobytes() and d.mocap_pos.tobytes() == live.mocap_pos.tobytes()
                  and d.mocap_quat.tobytes() == live.mocap_quat.tobytes()):
            d.qpos[:], d.mocap_pos[:], d.mocap_quat[:] = live.qpos, live.mocap_pos, live.mocap_quat
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
        jacp, jacr = self._jacobians
        mujoco.mj_jac(m, d, jacp, jacr, d.xipos[arm.vessel_body], arm.vessel_body)
        return jacp[:, arm.dof_adr].T @ np.asarray(force, dtype=float) + jacr[:, arm.dof_adr].T @ np.asarray(torque, dtype=float)

    def vessel_state(self, role: ArmRole) -> VesselState:
        """The held vessel's pose, velocity and centre of mass, world frame (valid after mj_forward/mj_step)."""
        arm, m, d = self.arms[role], self.model, self.data
        vel = np.empty(6)
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, arm.vessel_body, vel, 0)
        pos, quat = self.vessel_pose(role)
        return VesselState(pos=pos, quat=quat, lin_vel=vel[3:].copy(), ang_vel=vel[:3].copy(), com=self.vessel_com(role))

    def vessel_pose(self, role: ArmRole) -> tuple[np.ndarray, np.ndarray]:
        """The held vessel frame's world position (3,) m and orientation quaternion (4,) [w, x, y, z] (copies; valid
        after mj_forward or mj_kinematics, not mj_step alone, whose forward pass precedes its integration): :meth:`vessel_state` without the velocity, for the every-step exchange."""
        body, d = self.arms[role].vessel_body, self.data
        return d.xpos[body].copy(), d.xquat[body].copy()

    def vessel_com(self, role: ArmRole) -> np.ndarray:
        """(3,) m, world position of the held vessel body's centre of mass (the point ``xfrc_applied`` acts at)."""
        return self.data.xipos[self.arms[role].vessel_body].copy()

    def lip_position(self, role: ArmRole) -> np.ndarray:
        """(3,) m, world position of the held vessel's pour lip."""
        return self.data.site_xpos[self.arms[role].lip_site].copy()

    def apply_vessel_wrench(self, role: ArmRole, force: np.ndarray, torque: np.ndarray) -> None:
        """Set the external wrench on the vessel: ``force`` (3,) N and ``torque`` (3,) N m about the vessel's centre of
        mass, world frame. Replaces the previous one; it acts until changed (``data.xfrc_applied``)."""
        self.data.xfrc_applied[self.arms[role].vessel_body] = np.concatenate((force, torque))

    # ---- targets -------------------------------------------------------------------------------------------------
    def vessel_target(self, role: ArmRole, pose: PlanarPose) -> tuple[np.ndarray, np.ndarray]:
        """World pose (pos (3,) m, quat (4,)) of the vessel frame for ``pose`` relative to its home pose."""
        arm = self.arms[role]
        return planar_to_world(arm.home_pos, arm.home_quat, pose)

    def ik(self, role: ArmRole, settings: IKSettings | None = None) -> ArmIK:
        """The arm's IK solver (own private MjData) for its vessel frame site; cached for the default settings."""
        if settings is not None:
            arm = self.arms[role]
            return ArmIK(self.model, arm.joints, frame_site(arm.vessel), arm.home_q, settings)
        if role not in self._ik:
            arm = self.arms[role]
            self._ik[role] = ArmIK(self.model, arm.joints, frame_site(arm.vessel), arm.home_q, _TARGET_IK)
        return self._ik[role]

    def solve_vessel_target(self, role: ArmRole, pose: PlanarPose, seed_q: np.ndarray | None = None) -> np.ndarray:
        """Joint angles (n,) rad that put the vessel at ``pose`` (relative to home); ``InputError`` if unreachable.

        The solve starts from ``seed_q`` (default: the arm's current joint angles), which keeps the arm on its
        current IK branch; it never changes the live data.
        """
        arm = self.arms[role]
        pos, quat = self.vessel_target(role, pose)
        seed = self.joint_positions(role) if seed_q is None else np.asarray(seed_q, dtype=float)
        label = (
            f"{arm.vessel.name} target (dx={pose.dx:.3f} m, dz={pose.dz:.3f} m, tilt={math.degrees(pose.theta):.1f} deg)"
            f" for {role.value}"
        )
        return self.ik(role).solve_or_raise(pos, quat, seed, label)


# Convergence tolerances of vessel-target IK: well inside the acceptance (1 mm, 0.1 deg).
_TARGET_IK = IKSettings(position_tolerance=1e-5, rotation_tolerance=1e-5)
