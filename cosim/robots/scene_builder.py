"""Assemble a two-arm pour scene (MjSpec) from a :class:`SceneConfig`; the default one is ``models/scene.xml``.

What it builds (world z up, SI units):
* a floor, a table (box), lights;
* each arm's MJCF (the bundled UR10e's or a user's) checked against its mapping (the named joints and flange site)
  and attached at its base pose (position, and yaw or quaternion) with the name prefix ``<role>/``
  (``pour_arm/shoulder_pan``), its own keyframes dropped, its joint ranges and actuator force ranges set where the
  :class:`~cosim.robots.scene_config.ArmModel` gives them, a position servo added on each joint where it gives servo gains (a file without
  actuators); every arm link excluded from colliding with its parent link (explicitly: MuJoCo does not filter a
  child of a world-welded base);
* on each arm's flange site a mount body ``<role>/mount`` (an aluminium adapter plate along the flange axis) and
  the vessel body (:func:`cosim.robots.vessel_mjcf.add_vessel_body`), by default with the held wall against the
  plate at half the wall height, else at the placement's grasp; vessel contacts with the flange link are excluded
  (the vessel's own gripper/mount);
* custom ``text``/``numeric`` fields ``cosim/...`` recording the mapping (arm joints, the names the arms' ROS 2
  drivers give them, vessel, vessel geometry, joint speed limits), so :class:`cosim.robots.scene.RobotScene` can load
  any scene file this module wrote;
* a ``home`` keyframe: each arm's posture that puts its vessel frame at ``vessel_home`` aligned with the world axes,
  solved by inverse kinematics from ``home_seed``; servo targets equal to that posture.
"""

from __future__ import annotations

import math
from pathlib import Path
from urllib.parse import quote

import mujoco
import numpy as np

from cosim.checks import check_range
from cosim.errors import InputError
from cosim.robots import assets
from cosim.robots.ik import ArmIK, IKSettings
from cosim.robots.scene_config import ArmPlacement, MountSide, SceneConfig, default_scene_config
from cosim.robots.vessel_mjcf import add_vessel_body, frame_site
from cosim.vessel import VesselSpec

# Simulation options of every scene (implicitfast with stiff position servos; 2 ms step).
TIMESTEP = 0.002
# Name of the home keyframe.
HOME_KEY = "home"
# Prefix of the custom fields that record the scene mapping.
CUSTOM_PREFIX = "cosim"
# Tight tolerances for the home posture (it defines the vessels' home poses).
_HOME_IK = IKSettings(position_tolerance=1e-9, rotation_tolerance=1e-9, max_iterations=200, stall_iterations=30)

# Vessel frame axes (columns x, y, z) in the flange-site frame, per mount side. The flange z axis points into
# the held wall: BACK holds the -x wall (vessel x = site z), FRONT the +x wall (vessel x = -site z); vessel z (up)
# = site x in both.
_VESSEL_IN_SITE_ROT = {
    MountSide.BACK: np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]]),
    MountSide.FRONT: np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]),
}


def vessel_in_site(vessel: VesselSpec, side: MountSide, mount_thickness: float) -> tuple[np.ndarray, np.ndarray]:
    """Pose of the vessel frame in the flange-site frame: (pos (3,) m, quat (4,) [w, x, y, z]).

    The held wall's outer face (:func:`held_side_reach`) lies on the plate's far face (site z = ``mount_thickness``),
    the flange centre at half the wall height, in the vessel's mid plane y = 0.
    """
    rot = _VESSEL_IN_SITE_ROT[side]
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, rot.ravel())
    pos = np.array([-0.5 * vessel.inner_height, 0.0, mount_thickness + held_side_reach(vessel, side)])
    return pos, quat


def held_side_reach(vessel: VesselSpec, side: MountSide) -> float:
    """m, from the vessel's axis to its outermost point on the held side (-x for BACK, +x for FRONT): the wall's outer
    face, B / 2 + wall; a mesh vessel's farthest vertex that way, so that the mount plate rests on whatever sticks
    out of the wall there (a mug's handle) instead of passing through it."""
    if vessel.is_mesh:
        lo, hi = vessel.mesh.bounds[:, 0]
        return float(-lo if side is MountSide.BACK else hi)
    return 0.5 * vessel.inner_width + vessel.wall_thickness


def _base_quat(placement: ArmPlacement) -> list[float]:
    """The arm base's orientation [w, x, y, z]: ``base_quat``, else the rotation by ``base_yaw`` about world z."""
    if placement.base_quat is not None:
        return list(placement.base_quat)
    return [math.cos(0.5 * placement.base_yaw), 0.0, 0.0, math.sin(0.5 * placement.base_yaw)]


def _arm_field(placement: ArmPlacement) -> str:
    """How messages name the arm's settings: its label (a scene file's ``arms.pour``), else ``<role>.arm``."""
    return placement.arm.label or f"{placement.role.value}.arm"


def _resolve_mjcf(placement: ArmPlacement) -> Path:
    candidate = Path(placement.arm.mjcf)
    if not candidate.is_absolute():
        candidate = assets.models_dir() / candidate
    if not candidate.is_file():
        raise InputError(f"{_arm_field(placement)}.mjcf: file not found: {candidate}")
    return candidate


def _load_arm(placement: ArmPlacement) -> mujoco.MjSpec:
    """The arm's MJCF without its keyframes, checked against its mapping, with the joint ranges, torques and servos
    its :class:`ArmModel` asks for."""
    path = _resolve_mjcf(placement)
    field = _arm_field(placement)
    try:
        arm = mujoco.MjSpec.from_file(str(path))
        for key in list(arm.keys):
            arm.delete(key)
        alone = arm.compile()
    except ValueError as exc:
        raise InputError(f"{field}.mjcf {path}: not a loadable MJCF: {str(exc).splitlines()[0]}") from None
    _check_mapping(alone, placement, path)
    _apply_joint_settings(arm, alone, placement)
    return arm


def _check_mapping(alone: mujoco.MjModel, placement: ArmPlacement, path: Path) -> None:
    """Every named joint a hinge or slide of the arm file ``alone`` (compiled by itself), the flange site there."""
    field = _arm_field(placement)
    for joint in placement.arm.joints:
        jid = mujoco.mj_name2id(alone, mujoco.mjtObj.mjOBJ_JOINT, joint)
        if jid < 0:
            raise InputError(f"{field}.joints: no joint {joint!r} in {path}")
        if int(alone.jnt_type[jid]) not in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            raise InputError(f"{field}.joints: {joint!r} is not a hinge or slide joint")
    site = mujoco.mj_name2id(alone, mujoco.mjtObj.mjOBJ_SITE, placement.arm.flange_site)
    if site < 0:
        raise InputError(f"{field}.flange_site: no site {placement.arm.flange_site!r} in {path}")
    if not alone.body(int(alone.site_bodyid[site])).name:  # the vessel's mount is built on that body, by its name
        raise InputError(f"{field}.flange_site: the body that holds site {placement.arm.flange_site!r} in {path} has no name; "
                         "give it one")


def _joint_actuators(alone: mujoco.MjModel, joint_id: int) -> list[str]:
    return [alone.actuator(a).name or f"actuator {a}" for a in range(alone.nu)
            if alone.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT and alone.actuator_trnid[a, 0] == joint_id]


def _apply_joint_settings(arm: mujoco.MjSpec, alone: mujoco.MjModel, placement: ArmPlacement) -> None:
    """Set the joints' range and actuator force range where the arm model gives them (the range within the file's),
    and add the position servos (with gravity compensation through the actuators) where it gives servo gains; the
    file must then have no actuator on those joints, and without them it must have its own."""
    model, field = placement.arm, _arm_field(placement)
    to_file_units = math.degrees if arm.compiler.degree else float  # the file's own angle unit
    for i, name in enumerate(model.joints):
        jid = mujoco.mj_name2id(alone, mujoco.mjtObj.mjOBJ_JOINT, name)
        joint = arm.joint(name)
        if model.min_position:
            lo, hi = model.min_position[i], model.max_position[i]
            if alone.jnt_limited[jid]:
                file_lo, file_hi = (float(v) for v in alone.jnt_range[jid])
                check_range(f"{field}.min_position[{i}]", lo, file_lo, file_hi, f"rad (joint {name!r}'s range in the file)")
                check_range(f"{field}.max_position[{i}]", hi, file_lo, file_hi, f"rad (joint {name!r}'s range in the file)")
            joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            joint.range = [to_file_units(lo), to_file_units(hi)]
        if model.rated_torque:
            joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_TRUE
            joint.actfrcrange = [-model.rated_torque[i], model.rated_torque[i]]
        existing = _joint_actuators(alone, jid)
        if model.servo_kp:
            if existing:
                raise InputError(f"{field}.servo_kp: the arm file drives joint {name!r} with its own actuator "
                                 f"{existing[0]!r}; leave servo_kp and servo_kv out")
            servo = arm.add_actuator(name=f"{name}_servo", target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
            servo.set_to_position(kp=model.servo_kp[i], kv=model.servo_kv[i])
            joint.actgravcomp = True
        elif not existing:
            raise InputError(f"{field}.servo_kp: the arm file has no actuator on joint {name!r}; give each joint's "
                             f"servo gains (servo_kp in N m/rad, servo_kv in N m s/rad)")
    if model.servo_kp:  # gravity compensation of every moving body of the arm (the servos' model-based compensation)
        for body in range(1, alone.nbody):
            if alone.body_weldid[body] != 0:
                arm.body(alone.body(body).name).gravcomp = 1.0


def _add_environment(scene: mujoco.MjSpec, config: SceneConfig) -> None:
    scene.modelname = "cosim_pour_scene"
    scene.compiler.degree = False
    scene.compiler.autolimits = True
    scene.option.timestep = TIMESTEP
    scene.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    scene.visual.global_.offwidth = 1280
    scene.visual.global_.offheight = 960
    scene.stat.center = [0.15, 0.0, 1.1]
    scene.stat.extent = 1.6
    scene.add_texture(
        name="floor_checker", type=mujoco.mjtTexture.mjTEXTURE_2D, builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=[0.32, 0.34, 0.36], rgb2=[0.26, 0.28, 0.30], width=256, height=256,
    )
    floor_mat = scene.add_material(name="floor", texrepeat=[6, 6], reflectance=0.1)
    floor_mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "floor_checker"
    scene.add_material(name="table", rgba=[0.55, 0.42, 0.30, 1.0])
    world = scene.worldbody
    world.add_light(name="key", pos=[0.2, -1.5, 3.0], dir=[0.0, 0.45, -1.0], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    world.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[4.0, 4.0, 0.05], material="floor")
    t = config.table
    world.add_geom(
        name="table", type=mujoco.mjtGeom.mjGEOM_BOX, size=list(t.half_size),
        pos=[t.centre_xy[0], t.centre_xy[1], t.top - t.half_size[2]], material="table",
    )


def _exclude_neighbours(scene: mujoco.MjSpec, compiled: mujoco.MjModel, placement: ArmPlacement) -> None:
    """Exclude every arm link from colliding with its parent link.

    MuJoCo filters parent/child contacts itself except when the parent is welded to the world (an arm's fixed base),
    so the pairs are listed explicitly; pairs the arm's own file already excludes are kept once.
    """
    site_id = mujoco.mj_name2id(compiled, mujoco.mjtObj.mjOBJ_SITE, f"{placement.role.value}/{placement.arm.flange_site}")
    root = compiled.body_rootid[compiled.site_bodyid[site_id]]
    existing = set()
    for signature in compiled.exclude_signature:
        existing.add(frozenset((int(signature) >> 16, int(signature) & 0xFFFF)))  # (body1 << 16) + body2
    for body in range(1, compiled.nbody):
        parent = int(compiled.body_parentid[body])
        if compiled.body_rootid[body] == root and parent > 0 and frozenset((body, parent)) not in existing:
            scene.add_exclude(bodyname1=compiled.body(parent).name, bodyname2=compiled.body(body).name)


def _add_mount_and_vessel(scene: mujoco.MjSpec, compiled: mujoco.MjModel, placement: ArmPlacement, config: SceneConfig) -> str:
    """Build the mount plate and the vessel on the arm's flange site; return the flange link's body name."""
    role = placement.role.value
    site_id = mujoco.mj_name2id(compiled, mujoco.mjtObj.mjOBJ_SITE, f"{role}/{placement.arm.flange_site}")
    link_id = int(compiled.site_bodyid[site_id])
    link_name = compiled.body(link_id).name
    gravcomp = float(compiled.body_gravcomp[link_id])
    mount = scene.body(link_name).add_body(
        name=f"{role}/mount", pos=list(compiled.site_pos[site_id]), quat=list(compiled.site_quat[site_id])
    )
    mount.gravcomp = gravcomp
    m = config.mount
    mount.add_geom(
        name=f"{role}/mount_plate", type=mujoco.mjtGeom.mjGEOM_BOX, size=[m.half_width, m.half_width, 0.5 * m.thickness],
        pos=[0.0, 0.0, 0.5 * m.thickness], density=m.density, group=1, rgba=[0.6, 0.6, 0.62, 1.0],
    )
    pos, quat = vessel_in_site(placement.vessel, placement.mount_side, m.thickness)
    pos = pos if placement.grasp_pos is None else np.array(placement.grasp_pos)
    quat = quat if placement.grasp_quat is None else np.array(placement.grasp_quat)
    add_vessel_body(mount, placement.vessel, pos, quat, gravcomp=gravcomp, spec=scene)
    scene.add_exclude(bodyname1=link_name, bodyname2=placement.vessel.name)
    return link_name


def _vessel_record(vessel: VesselSpec) -> str:
    record = (
        f"name={vessel.name} shape={vessel.shape.value} inner_width={vessel.inner_width!r} "
        f"inner_depth={vessel.inner_depth!r} inner_height={vessel.inner_height!r} "
        f"wall_thickness={vessel.wall_thickness!r} wall_density={vessel.wall_density!r}"
    )
    if vessel.is_mesh:  # the file (its path URL-quoted: the record is split at spaces) and its pour direction
        record += f" mesh={quote(vessel.mesh.source)} pour_direction={vessel.mesh.pour_direction!r}"
    return record


def _add_mapping(scene: mujoco.MjSpec, placement: ArmPlacement, flange_link: str) -> None:
    role = placement.role.value
    joints = " ".join(f"{role}/{j}" for j in placement.arm.joints)
    scene.add_text(name=f"{CUSTOM_PREFIX}/{role}/joints", data=joints)
    scene.add_text(name=f"{CUSTOM_PREFIX}/{role}/driver_joints", data=" ".join(placement.arm.exported_joints))
    scene.add_text(name=f"{CUSTOM_PREFIX}/{role}/vessel", data=_vessel_record(placement.vessel))
    scene.add_text(name=f"{CUSTOM_PREFIX}/{role}/flange_link", data=flange_link)
    scene.add_numeric(
        name=f"{CUSTOM_PREFIX}/{role}/max_joint_speed", data=list(placement.arm.max_velocity),
        size=len(placement.arm.joints),
    )


def _home_posture(model: mujoco.MjModel, placement: ArmPlacement) -> np.ndarray:
    role = placement.role.value
    joints = tuple(f"{role}/{j}" for j in placement.arm.joints)
    seed = np.array(placement.home_seed)
    ik = ArmIK(model, joints, frame_site(placement.vessel), seed, _HOME_IK)
    return ik.solve_or_raise(
        np.array(placement.vessel_home), np.array([1.0, 0.0, 0.0, 0.0]), seed,
        f"{placement.home_field}: {role} home ({placement.vessel.name})",
    )


def _add_home_key(scene: mujoco.MjSpec, model: mujoco.MjModel, config: SceneConfig) -> None:
    qpos = model.qpos0.copy()
    ctrl = np.zeros(model.nu)
    for placement in config.placements:
        q = _home_posture(model, placement)
        for name, value in zip(placement.arm.joints, q):
            joint = model.joint(f"{placement.role.value}/{name}")
            qpos[model.jnt_qposadr[joint.id]] = value
            for act in range(model.nu):
                if model.actuator_trntype[act] == mujoco.mjtTrn.mjTRN_JOINT and model.actuator_trnid[act, 0] == joint.id:
                    ctrl[model.actuator_ctrladr[act]] = value
    scene.add_key(name=HOME_KEY, qpos=list(qpos), ctrl=list(ctrl))


def build_scene_spec(config: SceneConfig | None = None) -> mujoco.MjSpec:
    """The scene for ``config`` (default: :func:`default_scene_config`) as an MjSpec with its ``home`` keyframe."""
    config = config or default_scene_config()
    scene = mujoco.MjSpec()
    _add_environment(scene, config)
    for placement in config.placements:
        frame = scene.worldbody.add_frame(pos=list(placement.base_pos), quat=_base_quat(placement))
        scene.attach(_load_arm(placement), frame=frame, prefix=f"{placement.role.value}/")
    arms_only = scene.compile()
    for placement in config.placements:
        _exclude_neighbours(scene, arms_only, placement)
        flange_link = _add_mount_and_vessel(scene, arms_only, placement, config)
        _add_mapping(scene, placement, flange_link)
    _add_home_key(scene, scene.compile(), config)
    return scene


def scene_mjcf(config: SceneConfig | None = None) -> str:
    """MJCF text of the scene for ``config``, with a header naming its generator."""
    scene = build_scene_spec(config)
    scene.comment = (
        " GENERATED by `python -m cosim.tools.generate_models` from cosim.robots.scene_config.default_scene_config();"
        " do not edit.\n     Two UR10e-class arms (models/ur10e/ur10e.xml) on a table: pour_arm holds the pourer by its"
        " back wall, catch_arm the catcher by its front wall. World z up, SI units; the pour plane is x-z at y = 0. "
    )
    return scene.to_xml()
