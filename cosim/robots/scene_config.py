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

from cosim.checks import check_choice, check_number, check_positive, check_vector
from cosim.errors import InputError
from cosim.robots.ur10e import UR10E_DRIVER_JOINTS, UR10E_JOINTS, UR10E_MAX_JOINT_SPEED
from cosim.vessel import VesselSpec, default_catching_vessel, seed_pouring_vessel
from declared_settings.setting import REQUIRED, check_settings, documented, setting


class ArmRole(Enum):
    """The two arms of a pour; the value is the arm's name prefix in the scene (``pour_arm/shoulder_pan``)."""

    POUR = "pour_arm"
    CATCH = "catch_arm"


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


@dataclass(frozen=True)
class ArmPlacement:
    """One arm in the scene and the vessel it holds.

    role: :class:`ArmRole`.
    arm: :class:`ArmModel`.
    base_pos: (3,) m, world position of the arm's base frame.
    base_yaw: rad, rotation of the base frame about world z. [-2 pi, 2 pi]
    vessel: the held vessel's :class:`VesselSpec`.
    vessel_home: (3,) m, world position of the vessel frame origin at home (y must be 0: the pour plane).
    mount_side: :class:`MountSide`, the wall the flange holds.
    home_seed: (n,) rad, the joint configuration the home posture is solved from (picks the IK branch).
    base_quat: (4,) [w, x, y, z], the base frame's orientation in the world, instead of ``base_yaw``; None: the yaw.
    grasp_pos: (3,) m, the vessel frame's origin in the flange site's frame; None: the held wall's outer face (a mesh
        vessel's outermost point on that side) on the mount plate, the flange at half the wall height
        (:func:`cosim.robots.scene_builder.vessel_in_site`).
    grasp_quat: (4,) [w, x, y, z], the vessel frame's orientation in the flange site's frame; None: the mount side's
        (the flange's z axis into the held wall, the vessel's z along the site's x).
    home_field: the setting a home posture out of reach is blamed on in the message (a scene file's
        ``arms.pour.base_pos``).
    """

    role: ArmRole
    arm: ArmModel
    base_pos: tuple[float, float, float]
    base_yaw: float
    vessel: VesselSpec
    vessel_home: tuple[float, float, float]
    mount_side: MountSide
    home_seed: tuple[float, ...]
    base_quat: tuple[float, float, float, float] | None = None
    grasp_pos: tuple[float, float, float] | None = None
    grasp_quat: tuple[float, float, float, float] | None = None
    home_field: str = "placement"

    def __post_init__(self) -> None:
        p = self.arm.label if isinstance(self.arm, ArmModel) and self.arm.label else f"{getattr(self.role, 'value', self.role)}"
        object.__setattr__(self, "role", check_choice(f"{p}.role", self.role, ArmRole))
        object.__setattr__(self, "mount_side", check_choice(f"{p}.mount_side", self.mount_side, MountSide))
        object.__setattr__(self, "base_pos", check_vector(f"{p}.base_pos", self.base_pos, 3))
        yaw = check_number(f"{p}.base_yaw", self.base_yaw)
        if abs(yaw) > 2 * math.pi:
            raise InputError(f"{p}.base_yaw: must be in [-6.28319, 6.28319] rad, got {yaw:g}")
        object.__setattr__(self, "base_yaw", yaw)
        home = check_vector(f"{p}.vessel_home", self.vessel_home, 3)
        if abs(home[1]) > 1e-9:
            raise InputError(f"{p}.vessel_home[1]: the vessel must start in the pour plane y = 0, got {home[1]:g} m")
        object.__setattr__(self, "vessel_home", home)
        object.__setattr__(self, "home_seed", check_vector(f"{p}.home_seed", self.home_seed, len(self.arm.joints)))
        if not isinstance(self.vessel, VesselSpec):
            raise InputError(f"{p}.vessel: must be a VesselSpec, got {type(self.vessel).__name__}")
        if self.base_quat is not None:
            object.__setattr__(self, "base_quat", check_quat(f"{p}.base_quat", self.base_quat))
        if self.grasp_pos is not None:
            object.__setattr__(self, "grasp_pos", check_vector(f"{p}.grasp_pos", self.grasp_pos, 3))
        if self.grasp_quat is not None:
            object.__setattr__(self, "grasp_quat", check_quat(f"{p}.grasp_quat", self.grasp_quat))


@dataclass(frozen=True)
class TableSpec:
    """The table the arms stand on: a box. top: m, height of the top surface; centre_xy, half_size (3,) m."""

    top: float = 0.75
    centre_xy: tuple[float, float] = (0.15, 0.0)
    half_size: tuple[float, float, float] = (1.2, 0.6, 0.375)

    def __post_init__(self) -> None:
        object.__setattr__(self, "top", check_positive("table.top", self.top, "m", 3.0))
        object.__setattr__(self, "centre_xy", check_vector("table.centre_xy", self.centre_xy, 2))
        half = check_vector("table.half_size", self.half_size, 3)
        for i, v in enumerate(half):
            check_positive(f"table.half_size[{i}]", v, "m", 10.0)
        object.__setattr__(self, "half_size", half)


@dataclass(frozen=True)
class MountSpec:
    """The adapter plate between the tool flange and the vessel wall (aluminium, square).

    thickness: m, along the flange axis. (0, 0.05]; half_width: m. (0, 0.2]; density: kg/m^3. (0, 25000]
    """

    thickness: float = 0.01
    half_width: float = 0.04
    density: float = 2700.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "thickness", check_positive("mount.thickness", self.thickness, "m", 0.05))
        object.__setattr__(self, "half_width", check_positive("mount.half_width", self.half_width, "m", 0.2))
        object.__setattr__(self, "density", check_positive("mount.density", self.density, "kg/m^3", 25000.0))


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
