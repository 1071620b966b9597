"""A scene file's ``[arms.pour]`` and ``[arms.catch]``: which arm holds each vessel, where it stands, how it grasps.

Each section is the bundled UR10e (``mjcf`` left out) or a user's MJCF file (a MuJoCo Menagerie arm, or one's own)
with the mapping onto the project's conventions: its joint names (base to flange), its flange site (z out of the
tool flange), servo gains where the file has no actuators, and its limits (joint speed, acceleration, jerk, range,
rated torque, rated payload). Both kinds take a base pose (position, and yaw or quaternion), a home seed (the joint
configuration the home posture is solved from) and a grasp (the vessel frame in the flange site's frame). A key left
out keeps the project's cell: the UR10e at the cell's base pose holding its vessel on the mount plate, so a scene
without ``[arms]`` runs exactly the pour it ran before the section existed.

Conventions: world z up, SI units (m, rad, s, kg, N m), quaternions [w, x, y, z]. Where the limits go: the joint
speeds, ranges and torques into the arm's model (:class:`cosim.robots.scene_config.ArmModel`), so the inverse
kinematics, the reach check and the simulated drives keep them; the accelerations and jerks into the trajectory
limits (:func:`joint_limit_overrides`), under a scene's ``trajectory.limits``, which still override joint by joint.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field, replace
from pathlib import Path

from cosim.errors import InputError
from cosim.robots.scene_config import (
    ArmModel, ArmPlacement, ArmRole, SceneConfig, check_quat, ur10e_arm,
)
from cosim.robots.ur10e import UR10E_JOINTS, UR10E_PAYLOAD_KG
from cosim.trajectory.limits import (
    DEFAULT_ARM_MODEL, DEFAULT_MAX_ACCELERATION, DEFAULT_MAX_JERK, JointLimitOverride, JointLimits,
)
from declared_settings.setting import check_settings, documented, like, setting

ARM = "arm"
# Fields only a user's arm file takes (the bundled UR10e brings its own).
_USER_ARM_ONLY = ("joints", "flange_site", "driver_joints", "servo_kp", "servo_kv")


@documented
@dataclass(frozen=True)
class ArmSettings:
    """The arm holding one vessel: the bundled UR10e or a user's MJCF, its limits, where it stands, how it grasps.

    mjcf: the arm's MJCF file (a relative path is taken from the scene file's folder); '' is the bundled UR10e.
    joints: the arm's joint names in that file, base to flange (at least 6); [] for the UR10e.
    flange_site: a site on the arm's last link whose z axis points out of the tool flange; '' for the UR10e.
    driver_joints: the joints as the arm's ROS 2 driver names them, for trajectory.json and trajectory.mcap; []: the
      file's names (the UR10e: its driver's, 'shoulder_pan_joint' ...).
    base_quat: the base's orientation [w, x, y, z] instead of base_yaw (an arm on a wall or a ceiling); []: the yaw.
    grasp_quat: the vessel frame's orientation in the flange site's frame [w, x, y, z]; []: the flange's z axis
      into the held wall, the vessel's axis along the site's x.
    """

    mjcf: str = ""
    joints: tuple[str, ...] = ()
    flange_site: str = ""
    driver_joints: tuple[str, ...] = ()
    servo_kp: tuple[float, ...] = like(ArmModel, "servo_kp", (), "the file's own servos")
    servo_kv: tuple[float, ...] = like(ArmModel, "servo_kv", (), "the file's own servos")
    max_velocity: tuple[float, ...] = like(ArmModel, "max_velocity", (), "the UR10e's data sheet's (a user's arm must "
                                           "give it)")
    max_acceleration: tuple[float, ...] = like(JointLimits, "max_acceleration", (), f"{DEFAULT_MAX_ACCELERATION:g} "
                                               "each (cosim.trajectory.limits)", kind="per_joint")
    max_jerk: tuple[float, ...] = like(JointLimits, "max_jerk", (), f"{DEFAULT_MAX_JERK:g} each", kind="per_joint")
    min_position: tuple[float, ...] = like(ArmModel, "min_position", (), "the file's range")
    max_position: tuple[float, ...] = like(ArmModel, "max_position", (), "the file's range")
    rated_torque: tuple[float, ...] = like(ArmModel, "rated_torque", (), "the file's actuator force ranges (the "
                                           "simulated drives are clamped to it and the trajectories' inverse dynamics "
                                           "checked against it)")
    # at most a heavy industrial arm's payload
    rated_payload: float | None = setting(None, ARM, "The arm's rated payload, against the vessel, its liquid and the "
                                          "mount.", "kg", 0.0, 1000.0, lo_open=True,
                                          none_means=f"the UR10e's {UR10E_PAYLOAD_KG:g} kg (a user's arm must give it)")
    base_pos: tuple[float, ...] = like(ArmPlacement, "base_pos", (), "the project's cell (the UR10e's place by the "
                                       "table)")
    base_yaw: float | None = like(ArmPlacement, "base_yaw", None, "the cell's (pi for the pour arm, 0 for the catch "
                                  "arm) unless base_quat is given")
    base_quat: tuple[float, ...] = ()
    home_seed: tuple[float, ...] = like(ArmPlacement, "home_seed", (), "the UR10e's seed for the UR10e, zeros (the "
                                        "file's reference posture) for a user's arm")
    grasp_pos: tuple[float, ...] = like(ArmPlacement, "grasp_pos", (), "the held wall's outer face (a mesh vessel's "
                                        "outermost point on that side: a mug's handle) on the 10 mm mount plate, the "
                                        "flange at half the wall height (the pour arm holds the back wall, the catch "
                                        "arm the front wall)")
    grasp_quat: tuple[float, ...] = ()

    @property
    def is_user_arm(self) -> bool:
        """True for a user's MJCF, False for the bundled UR10e."""
        return bool(self.mjcf)

    @property
    def joint_count(self) -> int:
        """The arm's number of joints: the named joints of a user's arm, the UR10e's six."""
        return len(self.joints) if self.is_user_arm else len(UR10E_JOINTS)

    @property
    def payload_kg(self) -> float:
        """kg, the arm's rated payload: :attr:`rated_payload`, else the UR10e's."""
        return self.rated_payload if self.rated_payload is not None else UR10E_PAYLOAD_KG

    @property
    def arm_model(self) -> str:
        """What the exported trajectories call the arm: the user's MJCF file's name without its suffix, else UR10e."""
        return Path(self.mjcf).stem if self.is_user_arm else DEFAULT_ARM_MODEL

    def check(self, prefix: str) -> None:
        """Range and consistency checks that need no file, each message naming the field as ``<prefix>.<field>``."""
        if not isinstance(self.mjcf, str):
            raise InputError(f"{prefix}.mjcf: must be a path, got {self.mjcf!r}")
        if self.is_user_arm:
            for name, what in (("joints", "the arm's joint names, base to flange"),
                               ("flange_site", "the site on the last link, z out of the flange"),
                               ("max_velocity", "each joint's speed limit, rad/s")):
                if not getattr(self, name):
                    raise InputError(f"{prefix}.{name}: a user's arm ({prefix}.mjcf) needs {what}")
            if self.rated_payload is None:
                raise InputError(f"{prefix}.rated_payload: a user's arm ({prefix}.mjcf) needs its rated payload, kg")
        else:
            given = [name for name in _USER_ARM_ONLY if getattr(self, name)]
            if given:
                raise InputError(f"{prefix}.{given[0]}: the bundled UR10e brings its own; set {prefix}.mjcf to use "
                                 f"another arm's file")
        ArmModel(**self._model_fields(ur10e_arm(), prefix))  # the joints, speeds, servos, ranges, torques, names
        check_settings(self, prefix)  # the same declarations, and the limits and placement the model does not hold
        if self.base_yaw is not None and self.base_quat:
            raise InputError(f"{prefix}.base_quat: give base_yaw or base_quat, not both")
        if self.base_quat:
            check_quat(f"{prefix}.base_quat", self.base_quat)
        if self.grasp_quat:
            check_quat(f"{prefix}.grasp_quat", self.grasp_quat)

    def _model_fields(self, bundled: ArmModel, label: str) -> dict:
        """The :class:`ArmModel` fields of these settings, ``bundled`` standing for the UR10e's own."""
        if self.is_user_arm:
            base = dict(mjcf=self.mjcf, joints=self.joints, flange_site=self.flange_site, max_velocity=self.max_velocity,
                        driver_joints=self.driver_joints, servo_kp=self.servo_kp, servo_kv=self.servo_kv)
        else:
            base = {f.name: getattr(bundled, f.name) for f in dataclasses.fields(ArmModel)}
            base["max_velocity"] = self.max_velocity or bundled.max_velocity
        base.update(min_position=self.min_position, max_position=self.max_position, rated_torque=self.rated_torque,
                    label=label)
        return base

    def placement(self, cell: ArmPlacement, label: str) -> ArmPlacement:
        """The cell's arm placement ``cell`` (the UR10e's) with these settings; messages name them as ``label``."""
        if self == ArmSettings():
            return cell
        model = ArmModel(**self._model_fields(cell.arm, label))
        seed = self.home_seed or (cell.home_seed if not self.is_user_arm else (0.0,) * self.joint_count)
        return replace(
            cell,
            arm=model,
            base_pos=self.base_pos or cell.base_pos,
            base_yaw=cell.base_yaw if self.base_yaw is None else self.base_yaw,
            base_quat=self.base_quat or None,
            home_seed=seed,
            grasp_pos=self.grasp_pos or None,
            grasp_quat=self.grasp_quat or None,
            home_field=self.reach_field(label),
        )

    def reach_field(self, label: str) -> str:
        """The setting a pose out of this arm's reach is blamed on: the placement of the vessels where the section is
        not set; its home posture's IK seed where that alone is set (the seed picks the posture the checks start
        from); else its base position (its arm or its base is the user's)."""
        if self == ArmSettings():
            return "placement"
        return f"{label}.home_seed" if self == replace(ArmSettings(), home_seed=self.home_seed) else f"{label}.base_pos"

    def with_folder(self, folder: Path) -> "ArmSettings":
        """These settings with a relative :attr:`mjcf` taken from ``folder`` (the scene file's)."""
        if not self.is_user_arm or Path(self.mjcf).is_absolute():
            return self
        return replace(self, mjcf=os.path.abspath(folder / self.mjcf))

    def limit_overrides(self, arm: str, joints: tuple[str, ...]) -> dict[str, JointLimitOverride]:
        """Per joint (``<arm>/<joint>``, ``joints`` the scene's full names), the acceleration and jerk limits these
        settings give (the others are in the arm's model)."""
        out = {}
        for i, name in enumerate(joints):
            values = {f: getattr(self, f)[i] for f in ("max_acceleration", "max_jerk") if getattr(self, f)}
            if values:
                out[name] = JointLimitOverride(**values)
        return out


@dataclass(frozen=True)
class ArmsSettings:
    """pour: the arm that holds and tilts the pourer (default: the bundled UR10e behind it, at -x).
    catch: the arm that holds and moves the catcher (default: the bundled UR10e beyond it, at +x).
    """

    pour: ArmSettings = field(default_factory=ArmSettings)
    catch: ArmSettings = field(default_factory=ArmSettings)

    def __post_init__(self) -> None:
        for role in ArmRole:
            self.of(role).check(self.label(role))

    def of(self, role: ArmRole) -> ArmSettings:
        """The settings of ``role``'s arm."""
        return self.pour if role is ArmRole.POUR else self.catch

    @staticmethod
    def label(role: ArmRole) -> str:
        """How messages name ``role``'s section: ``arms.pour`` or ``arms.catch``."""
        return f"arms.{'pour' if role is ArmRole.POUR else 'catch'}"

    def apply(self, cell: SceneConfig) -> SceneConfig:
        """The project's cell ``cell`` with these arms."""
        return replace(cell, pour=self.pour.placement(cell.pour, self.label(ArmRole.POUR)),
                       catch=self.catch.placement(cell.catch, self.label(ArmRole.CATCH)))

    def with_folder(self, folder: Path) -> "ArmsSettings":
        """These settings with relative arm files taken from ``folder`` (the scene file's)."""
        return ArmsSettings(self.pour.with_folder(folder), self.catch.with_folder(folder))

    def reach_fields(self) -> dict[ArmRole, str]:
        """Per arm, the setting a pose out of its reach is blamed on (:meth:`ArmSettings.reach_field`)."""
        return {role: self.of(role).reach_field(self.label(role)) for role in ArmRole}
