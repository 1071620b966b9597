"""Configuration of a two-arm pour scene: which arm models, where they stand, which vessels they hold.

Frozen dataclasses validated in ``__post_init__`` (messages name the field and the allowed range), closed choices
as enums. Conventions: world z up, SI units, angles in rad. Pour plane = world x-z plane at y = 0; the pour
direction is world +x. At home each vessel's frame is aligned with the world axes (+x toward its lip, +z up) and its
origin (centre of the inner floor) is at ``vessel_home``.

:func:`default_scene_config` is the project's scene (``models/scene.xml``): two UR10e-class arms on a table, the
pour arm behind the pourer (at -x) holding it by the back wall, the catch arm beyond the catcher (at +x) holding it
by the front wall; the pourer's lip stands :data:`POUR_HEIGHT` above the catcher's rim. :func:`pour_cell_config`
builds the same cell around other vessels and places them (a scene file's ``[vessels]`` and ``[placement]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

from cosim.checks import check_choice, check_vector
from cosim.errors import InputError
from cosim.robots.ur10e import UR10E_DRIVER_JOINTS, UR10E_JOINTS, UR10E_MAX_JOINT_SPEED
from cosim.vessel import VesselSpec, default_catching_vessel, seed_pouring_vessel
from declared_settings.setting import REQUIRED, check_settings, documented, setting


class ArmRole(Enum):
    """The two arms of a pour; the value is the arm's name prefix in the scene (``pour_arm/shoulder_pan``)."""

    POUR = "pour_arm"
    CATCH = "catch_arm"

    # hashed by identity, as the members compare (Enum's own hash is a Python function of the name, and the step
    # loop looks the arms' parts up by role some thirty times a MuJoCo step); dicts keep their insertion order
    __hash__ = object.__hash__


class MountSide(Enum):
    """Which vessel wall the arm's flange holds: the flange's z axis points into that wall."""

    BACK = "back"  # the -x wall: the arm reaches from behind (-x), the lip side stays free
    FRONT = "front"  # the +x wall: the arm reaches from +x


ARM = "arm"


@documented
@dataclass(frozen=True)
class ArmModel:
    """An arm MJCF and how it maps onto the project's conventions. The per-joint settings' accepted ranges are
    generous bounds that still reject typos by orders of magnitude.

    mjcf: path of the arm's MJCF; a relative path is resolved against the project's models directory.
    joints: the arm's joint names in that file, base to tip (n >= 6); each driven by a position servo: the file's own
        (an actuator with ``biastype="affine"`` and bias -kp on the joint) or the one :attr:`servo_kp` asks for.
    flange_site: a site on the last link whose z axis points out of the tool flange; the vessel mount is built on it.
    driver_joints: the same joints as the arm's ROS 2 driver names them (n, without its tf prefix), for the exported
        trajectories; empty: the MJCF's names.
    label: how messages name this arm's settings (a scene file's ``arms.pour``); empty: ``arm``.
    """

    mjcf: str
    joints: tuple[str, ...]
    flange_site: str
    max_velocity: tuple[float, ...] = setting(
        REQUIRED, ARM, "The joint speed limit, for trajectory generation (MuJoCo models have no speed limits).", "rad/s",
        0.0, 50.0, lo_open=True, kind="per_joint")
    driver_joints: tuple[str, ...] = ()
    servo_kp: tuple[float, ...] = setting(
        (), ARM, "For a file without actuators on its joints, the scene adds a position servo tau = kp (u - q) - kv "
        "qdot on each, with gravity compensation through the actuators (body gravcomp, joint actuatorgravcomp), as an "
        "arm's controller compensates gravity from its dynamic model; given with servo_kv.", "N m/rad", 0.0, 1.0e7,
        lo_open=True, kind="per_joint", none_means="the file's own servos")
    servo_kv: tuple[float, ...] = setting((), ARM, "The added servos' damping, with servo_kp.", "N m s/rad", 0.0, 1.0e6,
                                          kind="per_joint", none_means="the file's own servos")
    min_position: tuple[float, ...] = setting((), ARM, "The joints' lower limits, within the file's range.", "rad",
                                              -100.0, 100.0, kind="per_joint", none_means="the file's range")
    max_position: tuple[float, ...] = setting((), ARM, "The joints' upper limits, with min_position.", "rad",
                                              -100.0, 100.0, kind="per_joint", none_means="the file's range")
    rated_torque: tuple[float, ...] = setting((), ARM, "The most each joint's drive delivers (the joint's actuator "
                                              "force range).", "N m", 0.0, 1.0e5, lo_open=True, kind="per_joint",
                                              none_means="the file's actuator force ranges")
    label: str = ""

    def __post_init__(self) -> None:
        p = self.field_prefix
        if not isinstance(self.mjcf, str) or not self.mjcf:
            raise InputError(f"{p}.mjcf: must be a path, got {self.mjcf!r}")
        if len(self.joints) < 6 or not all(isinstance(j, str) and j for j in self.joints):
            raise InputError(f"{p}.joints: must name at least 6 joints, got {list(self.joints)}")
        if len(set(self.joints)) != len(self.joints):
            raise InputError(f"{p}.joints: names must be unique, got {list(self.joints)}")
        if not isinstance(self.flange_site, str) or not self.flange_site:
            raise InputError(f"{p}.flange_site: must be a site name, got {self.flange_site!r}")
        n = len(self.joints)
        object.__setattr__(self, "joints", tuple(self.joints))
        check_settings(self, p)
        driver = tuple(self.driver_joints)
        named = all(isinstance(j, str) and j and not any(c.isspace() for c in j) for j in driver)
        if driver and (not named or len(driver) != n or len(set(driver)) != len(driver)):
            raise InputError(f"{p}.driver_joints: must name the arm's {n} joints once each, without spaces, got {list(driver)}")
        object.__setattr__(self, "driver_joints", driver)
        if len(self.servo_kp) != len(self.servo_kv):
            raise InputError(f"{p}.servo_kv: give servo_kp and servo_kv together, one of each per joint ({n})")
        if bool(self.min_position) != bool(self.max_position):
            raise InputError(f"{p}.max_position: give min_position and max_position together, one of each per joint ({n})")
        for i, (lo, hi) in enumerate(zip(self.min_position, self.max_position)):
            if not lo < hi:
                raise InputError(f"{p}.max_position[{i}]: must be above min_position[{i}] = {lo:g} rad, got {hi:g}")

    @property
    def joint_count(self) -> int:
        """The arm's number of joints (each per-joint setting gives one number per joint)."""
        return len(self.joints)

    @property
    def field_prefix(self) -> str:
        """How messages name these settings: :attr:`label`, else ``arm``."""
        return self.label or "arm"

    @property
    def exported_joints(self) -> tuple[str, ...]:
        """The joint names the exported trajectories use (before the prefix): :attr:`driver_joints`, else the MJCF's."""
        return self.driver_joints or self.joints


def check_quat(field: str, values: object) -> tuple[float, ...]:
    """A rotation as a quaternion [w, x, y, z], normalised; InputError for a zero one."""
    quat = check_vector(field, values, 4)
    norm = math.sqrt(sum(v * v for v in quat))
    if norm < 1e-9:
        raise InputError(f"{field}: must be a rotation [w, x, y, z] (not all zero), got {list(quat)}")
    return tuple(v / norm for v in quat)


def ur10e_arm() -> ArmModel:
    """The project's UR10e-class arm (``models/ur10e/ur10e.xml``)."""
    return ArmModel("ur10e/ur10e.xml", UR10E_JOINTS, "flange", UR10E_MAX_JOINT_SPEED, UR10E_DRIVER_JOINTS)


@documented
@dataclass(frozen=True)
class ArmPlacement:
    """One arm in the scene and the vessel it holds.

    role: :class:`ArmRole`.
    arm: :class:`ArmModel`.
    vessel: the held vessel's :class:`VesselSpec`.
    mount_side: :class:`MountSide`, the wall the flange holds.
    base_quat: (4,) [w, x, y, z], the base frame's orientation in the world, instead of ``base_yaw``; None: the yaw.
    grasp_quat: (4,) [w, x, y, z], the vessel frame's orientation in the flange site's frame; None: the mount side's
        (the flange's z axis into the held wall, the vessel's z along the site's x).
    home_field: the setting a home posture out of reach is blamed on in the message (a scene file's
        ``arms.pour.base_pos``).
    """

    role: ArmRole
    arm: ArmModel
    base_pos: tuple[float, float, float] = setting(REQUIRED, ARM, "The arm base's world position [x, y, z].", "m",
                                                   kind="vector")
    base_yaw: float = setting(REQUIRED, ARM, "The base's rotation about world z.", "rad", -2.0 * math.pi, 2.0 * math.pi)
    vessel: VesselSpec
    vessel_home: tuple[float, float, float] = setting(
        REQUIRED, ARM, "World position [x, y, z] of the held vessel's frame origin at home (y = 0: the pour plane).",
        "m", kind="vector")
    mount_side: MountSide
    home_seed: tuple[float, ...] = setting(
        REQUIRED, ARM, "The configuration the home posture is solved from (picks the inverse kinematics' branch: elbow "
        "up or down).", "rad", -100.0, 100.0, kind="per_joint")
    base_quat: tuple[float, float, float, float] | None = None
    grasp_pos: tuple[float, float, float] | None = setting(
        None, ARM, "Where the vessel sits on the flange: its frame's origin (the centre of its inner floor) in the "
        "flange site's frame [x, y, z].", "m", kind="vector", none_means="the held wall's outer face (a mesh vessel's "
        "outermost point on that side) on the mount plate, the flange at half the wall height "
        "(cosim.robots.scene_builder.vessel_in_site)")
    grasp_quat: tuple[float, float, float, float] | None = None
    home_field: str = "placement"

    def __post_init__(self) -> None:
        p = self.arm.label if isinstance(self.arm, ArmModel) and self.arm.label else f"{getattr(self.role, 'value', self.role)}"
        if not isinstance(self.arm, ArmModel):
            raise InputError(f"{p}.arm: must be an ArmModel, got {type(self.arm).__name__}")
        if not isinstance(self.vessel, VesselSpec):
            raise InputError(f"{p}.vessel: must be a VesselSpec, got {type(self.vessel).__name__}")
        object.__setattr__(self, "role", check_choice(f"{p}.role", self.role, ArmRole))
        object.__setattr__(self, "mount_side", check_choice(f"{p}.mount_side", self.mount_side, MountSide))
        check_settings(self, p)
        if abs(self.vessel_home[1]) > 1e-9:
            raise InputError(f"{p}.vessel_home[1]: the vessel must start in the pour plane y = 0, got {self.vessel_home[1]:g} m")
        if self.base_quat is not None:
            object.__setattr__(self, "base_quat", check_quat(f"{p}.base_quat", self.base_quat))
        if self.grasp_quat is not None:
            object.__setattr__(self, "grasp_quat", check_quat(f"{p}.grasp_quat", self.grasp_quat))

    @property
    def joint_count(self) -> int:
        """The held arm's number of joints (the home seed gives one angle per joint)."""
        return self.arm.joint_count


TABLE = "table"


@documented
@dataclass(frozen=True)
class TableSpec:
    """The table the arms stand on: a box."""

    top: float = setting(0.75, TABLE, "Height of the table's top surface.", "m", 0.0, 3.0, lo_open=True)
    centre_xy: tuple[float, float] = setting((0.15, 0.0), TABLE, "The table's centre in the horizontal plane [x, y].",
                                             "m")
    half_size: tuple[float, float, float] = setting((1.2, 0.6, 0.375), TABLE, "The box's half sizes [x, y, z].", "m",
                                                    0.0, 10.0, lo_open=True, kind="components")

    def __post_init__(self) -> None:
        check_settings(self, "table")


MOUNT = "mount"


@documented
@dataclass(frozen=True)
class MountSpec:
    """The adapter plate between the tool flange and the vessel wall (aluminium, square)."""

    thickness: float = setting(0.01, MOUNT, "The plate's thickness along the flange axis.", "m", 0.0, 0.05,
                               lo_open=True)
    half_width: float = setting(0.04, MOUNT, "Half the plate's side.", "m", 0.0, 0.2, lo_open=True)
    density: float = setting(2700.0, MOUNT, "The plate's density (aluminium's).", "kg/m^3", 0.0, 25000.0,
                             lo_open=True)

    def __post_init__(self) -> None:
        check_settings(self, "mount")


@dataclass(frozen=True)
class SceneConfig:
    """The whole scene: both arm placements, the table, the vessel mount."""

    pour: ArmPlacement
    catch: ArmPlacement
    table: TableSpec = field(default_factory=TableSpec)
    mount: MountSpec = field(default_factory=MountSpec)

    def __post_init__(self) -> None:
        if self.pour.role is not ArmRole.POUR:
            raise InputError(f"scene.pour.role: must be {ArmRole.POUR.value!r}, got {self.pour.role.value!r}")
        if self.catch.role is not ArmRole.CATCH:
            raise InputError(f"scene.catch.role: must be {ArmRole.CATCH.value!r}, got {self.catch.role.value!r}")
        if self.pour.vessel.name == self.catch.vessel.name:
            raise InputError(f"scene: the two vessels need different names, both are {self.pour.vessel.name!r}")

    @property
    def placements(self) -> tuple[ArmPlacement, ArmPlacement]:
        return (self.pour, self.catch)


# ---- the project's default layout ----------------------------------------------------------------------------------
# Height of the table top the arms stand on, m.
TABLE_TOP = 0.75
# Height of the pourer's inner floor at home above the table top, m.
POURER_FLOOR_ABOVE_TABLE = 0.50
# The default pour height, m: the pourer's lip above the catcher's rim at home. The catcher's rim then sits 0.21 m
# below the pourer's floor: tilting the pourer 120 deg about its bottom middle brings its lip 0.183 m below the floor
# (lip_local rotated by R_y(120 deg)), so 0.21 m keeps 27 mm of clearance and the pourer can tilt 0-120 deg about
# either pivot above the catcher. The lip-to-rim fall at home is 0.191 + 0.21 = 0.401 m; a controller lowers the
# pourer (dz < 0) to shorten it.
POUR_HEIGHT = 0.401
# Catcher centre at home, m along +x from the pourer's centre: under the lip (0.1005 m) plus the stream's throw.
CATCHER_HOME_X = 0.20
# The arms' bases in the horizontal plane, m (x, y), and their yaw, rad: the pour arm behind the pourer (-x), its
# shoulder offset (the UR10e's d4) bringing the wrist into the pour plane; the catch arm beyond the catcher (+x).
POUR_ARM_BASE_XY = (-0.62, -0.17415)
CATCH_ARM_BASE_XY = (0.95, 0.17415)
# The joint configuration both arms' home postures are solved from (picks the elbow-up IK branch), rad.
HOME_SEED = (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)


def pour_cell_config(
    pourer: VesselSpec,
    catcher: VesselSpec,
    table_top: float = TABLE_TOP,
    pourer_floor_above_table: float = POURER_FLOOR_ABOVE_TABLE,
    catcher_home_x: float = CATCHER_HOME_X,
    pour_height: float = POUR_HEIGHT,
) -> SceneConfig:
    """The project's two-UR10e cell holding ``pourer`` and ``catcher``, placed by (all m): ``table_top``, the height
    of the table the arms stand on; ``pourer_floor_above_table``, the pourer's inner floor at home above it;
    ``catcher_home_x``, the catcher's centre at home along the pour direction from the pourer's; ``pour_height``, the
    pourer's lip above the catcher's rim at home (the catcher's floor is then at the pourer's floor + its inner
    height - ``pour_height`` - the catcher's inner height)."""
    pourer_floor = table_top + pourer_floor_above_table
    catcher_rim = pourer_floor + pourer.inner_height - pour_height
    catcher_floor = catcher_rim - catcher.inner_height
    return SceneConfig(
        pour=ArmPlacement(
            role=ArmRole.POUR,
            arm=ur10e_arm(),
            base_pos=(*POUR_ARM_BASE_XY, table_top),
            base_yaw=math.pi,
            vessel=pourer,
            vessel_home=(0.0, 0.0, pourer_floor),
            mount_side=MountSide.BACK,
            home_seed=HOME_SEED,
        ),
        catch=ArmPlacement(
            role=ArmRole.CATCH,
            arm=ur10e_arm(),
            base_pos=(*CATCH_ARM_BASE_XY, table_top),
            base_yaw=0.0,
            vessel=catcher,
            vessel_home=(catcher_home_x, 0.0, catcher_floor),
            mount_side=MountSide.FRONT,
            home_seed=HOME_SEED,
        ),
        table=TableSpec(top=table_top, half_size=(1.2, 0.6, 0.5 * table_top)),
    )


def default_scene_config() -> SceneConfig:
    """The project's scene: UR10e-class arms, the paper's pouring vessel and the default catching vessel."""
    return pour_cell_config(seed_pouring_vessel(), default_catching_vessel())
