"""Per-joint kinematic limits of an arm for trajectory generation and checking.

Units: positions rad, velocities rad/s, accelerations rad/s^2, jerks rad/s^3, torques N m; all limits are symmetric
(``|qd| <= max_velocity`` and so on); joint positions must stay in ``[min_position, max_position]``.

Defaults for a UR10e-class arm (:func:`arm_limits`):

* ``max_velocity``: the arm's data-sheet joint speed as recorded in the scene (``ArmInfo.max_joint_speed``; UR10e:
  120 deg/s base and shoulder, 180 deg/s elbow and wrists, see :mod:`cosim.robots.ur10e`).
* ``max_acceleration``: :data:`DEFAULT_MAX_ACCELERATION`. Universal Robots publish no joint acceleration limit (the
  joints are torque-limited); their own ROS 2 driver gives MoveIt 5.0 rad/s^2 on every joint, values "chosen
  conservatively to work in most use cases" (UniversalRobots/Universal_Robots_ROS2_Driver,
  ``ur_moveit_config/config/joint_limits.yaml``).
* ``max_jerk``: :data:`DEFAULT_MAX_JERK`. No arm maker in this class publishes one; 100 rad/s^3 is MoveIt's default
  for its ruckig smoothing (moveit/moveit, ``moveit_core/trajectory_processing/src/ruckig_traj_smoothing.cpp``,
  ``DEFAULT_MAX_JERK``), far below the thousands of rad/s^3 that arms with published jerk limits allow. It ramps the
  acceleration from 0 to 5 rad/s^2 in 50 ms.
* ``rated_torque``: the torque the joint's drive may deliver, the model's joint actuator force range
  (``actuatorfrcrange``; UR10e: :data:`cosim.robots.ur10e.UR10E_RATED_TORQUE`, 330 N m base and shoulder, 150 N m
  elbow, 56 N m wrists). The inverse dynamics of a trajectory (:mod:`cosim.trajectory.torques`) is checked against it.
* ``min_position``/``max_position``: the MuJoCo model's joint range (UR10e: +-360 deg). ruckig's community build
  ignores position limits, so :class:`cosim.trajectory.generator.TrajectoryGenerator` clamps its targets to them
  and :func:`cosim.trajectory.checks.check_trajectory` verifies the result.

Every default can be overridden per joint with :class:`JointLimitOverride` (the scene file's trajectory limits map
onto it); overrides may not widen the position range beyond the model's joint range.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING

from cosim.checks import check_range
from cosim.errors import InputError
from cosim.robots.scene_config import ARM, ArmModel, ArmRole
from declared_settings.setting import REQUIRED, check_settings, declared, documented, like, setting

if TYPE_CHECKING:
    import numpy as np

    from cosim.robots.scene import RobotScene

DEFAULT_MAX_ACCELERATION = 5.0  # rad/s^2, see the module docstring
DEFAULT_MAX_JERK = 100.0  # rad/s^3, see the module docstring
DEFAULT_ARM_MODEL = "UR10e"  # the arm of the project's scene (models/ur10e/ur10e.xml)

LIMIT_FIELDS = ("max_velocity", "max_acceleration", "max_jerk", "min_position", "max_position", "rated_torque")

RATED_TORQUE = replace(declared(ArmModel, "rated_torque"), kind="float")  # one joint's, as the arm model declares it


@documented
@dataclass(frozen=True)
class JointLimits:
    """Limits of one joint (the arm model's per-joint settings, one joint's). name: full joint name
    ``<arm>/<joint>``. rated_torque: N m, the torque the joint's drive may deliver, within the arm model's range, or
    inf for a coordinate that is no motor's (a task-space filter's)."""

    name: str
    max_velocity: float = like(ArmModel, "max_velocity", kind="float")
    # generous bounds that still reject typos by orders of magnitude
    max_acceleration: float = setting(REQUIRED, ARM, "Joint acceleration limit.", "rad/s^2", 0.0, 1000.0, lo_open=True)
    max_jerk: float = setting(REQUIRED, ARM, "Joint jerk limit.", "rad/s^3", 0.0, 1.0e6, lo_open=True)
    min_position: float = like(ArmModel, "min_position", kind="float")
    max_position: float = setting(REQUIRED, ARM, "The joint's upper limit.", "rad", "min_position",
                                  declared(ArmModel, "max_position").bounds.hi, lo_open=True)
    rated_torque: float = math.inf

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InputError(f"limits: joint name must be a non-empty string, got {self.name!r}")
        p = f"limits.{self.name}"
        check_settings(self, p)
        if self.rated_torque != math.inf:
            object.__setattr__(self, "rated_torque", RATED_TORQUE.check(f"{p}.rated_torque", self.rated_torque))


@dataclass(frozen=True)
class ArmLimits:
    """Limits of every joint of one arm, base to tip.

    arm: the arm's name prefix (``pour_arm``). arm_model: what arm the limits describe (e.g. ``UR10e``), for export.
    joints: one :class:`JointLimits` per joint, names ``<arm>/<joint>`` in the scene's joint order.
    """

    arm: str
    arm_model: str
    joints: tuple[JointLimits, ...]

    def __post_init__(self) -> None:
        if not isinstance(self.arm, str) or not self.arm or "/" in self.arm:
            raise InputError(f"limits.arm: must be an arm name without '/', got {self.arm!r}")
        if not isinstance(self.arm_model, str) or not self.arm_model:
            raise InputError(f"limits.{self.arm}.arm_model: must be a non-empty string, got {self.arm_model!r}")
        joints = tuple(self.joints)
        if not joints or not all(isinstance(j, JointLimits) for j in joints):
            raise InputError(f"limits.{self.arm}.joints: must be a non-empty sequence of JointLimits")
        names = [j.name for j in joints]
        if len(set(names)) != len(names) or not all(n.startswith(f"{self.arm}/") for n in names):
            raise InputError(f"limits.{self.arm}.joints: names must be unique and start with '{self.arm}/', got {names}")
        object.__setattr__(self, "joints", joints)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Full joint names, base to tip."""
        return tuple(j.name for j in self.joints)

    def array(self, field: str) -> np.ndarray:
        """(n,) values of one limit field (one of :data:`LIMIT_FIELDS`), base to tip."""
        import numpy as np

        if field not in LIMIT_FIELDS:
            raise ValueError(f"unknown limit field {field!r}; one of {LIMIT_FIELDS}")
        return np.array([getattr(j, field) for j in self.joints])


@dataclass(frozen=True)
class JointLimitOverride:
    """Replacements for some of a joint's default limits; ``None`` keeps the default. Units as :class:`JointLimits`;
    values are validated when applied (:func:`arm_limits`)."""

    max_velocity: float | None = None
    max_acceleration: float | None = None
    max_jerk: float | None = None
    min_position: float | None = None
    max_position: float | None = None
    rated_torque: float | None = None

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
                raise InputError(f"limits override {f.name}: must be a number or None, got {value!r}")


def _model_torque(scene: RobotScene, joint: str) -> float:
    """N m, the largest torque the model's actuators may put on ``joint`` (its actuator force range), inf if unlimited."""
    import numpy as np

    model = scene.model
    jid = model.joint(joint).id
    if not model.jnt_actfrclimited[jid]:
        return math.inf
    return float(np.max(np.abs(model.jnt_actfrcrange[jid])))


def _model_range(scene: RobotScene, joint: str) -> tuple[float, float]:
    model = scene.model
    jid = model.joint(joint).id
    if not model.jnt_limited[jid]:
        return -math.inf, math.inf
    lo, hi = model.jnt_range[jid]
    return float(lo), float(hi)


def arm_limits(
    scene: RobotScene,
    role: ArmRole,
    overrides: Mapping[str, JointLimitOverride] | None = None,
    arm_model: str = DEFAULT_ARM_MODEL,
) -> ArmLimits:
    """Default limits of ``role``'s arm in ``scene`` (see the module docstring), with per-joint ``overrides``.

    overrides: joint name (short, ``elbow``, or full, ``pour_arm/elbow``) -> :class:`JointLimitOverride`. An unknown
    joint, a bad value or a position range wider than the model's joint range raises ``InputError``.
    """
    arm = scene.arms[role]
    prefix = f"{role.value}/"
    full = {name.removeprefix(prefix): name for name in arm.joints}
    by_joint: dict[str, JointLimitOverride] = {}
    for key, override in (overrides or {}).items():
        name = key if key in arm.joints else full.get(key)
        if name is None:
            raise InputError(f"limits.{role.value}: unknown joint {key!r}; the arm has {', '.join(full)}")
        if not isinstance(override, JointLimitOverride):
            raise InputError(f"limits.{name}: must be a JointLimitOverride, got {type(override).__name__}")
        by_joint[name] = override
    joints = []
    for i, name in enumerate(arm.joints):
        override = by_joint.get(name, JointLimitOverride())
        lo, hi = _model_range(scene, name)
        values = {
            "max_velocity": float(arm.max_joint_speed[i]),
            "max_acceleration": DEFAULT_MAX_ACCELERATION,
            "max_jerk": DEFAULT_MAX_JERK,
            "min_position": lo,
            "max_position": hi,
            "rated_torque": _model_torque(scene, name),
        }
        values.update({f: getattr(override, f) for f in LIMIT_FIELDS if getattr(override, f) is not None})
        for f in ("min_position", "max_position"):
            if not math.isfinite(values[f]) and getattr(override, f) is None:
                raise InputError(f"limits.{name}.{f}: the model's joint has no range; give one (arms.*.{f} or trajectory.limits)")
            check_range(f"limits.{name}.{f}", values[f], lo, hi, "rad (the model's joint range)")
        if not math.isfinite(values["rated_torque"]):
            raise InputError(f"limits.{name}.rated_torque: the model's joint has no actuator force range; give one "
                             f"(arms.*.rated_torque or trajectory.limits)")
        joints.append(JointLimits(name=name, **values))
    return ArmLimits(arm=role.value, arm_model=arm_model, joints=tuple(joints))


def scene_limits(
    scene: RobotScene,
    overrides: Mapping[ArmRole, Mapping[str, JointLimitOverride]] | None = None,
    arm_models: Mapping[ArmRole, str] | None = None,
) -> dict[ArmRole, ArmLimits]:
    """:func:`arm_limits` of both arms, in :class:`ArmRole` order (the trajectory files' column order); ``arm_models``
    names each arm's model (default :data:`DEFAULT_ARM_MODEL`)."""
    overrides, arm_models = overrides or {}, arm_models or {}
    return {role: arm_limits(scene, role, overrides.get(role), arm_models.get(role, DEFAULT_ARM_MODEL)) for role in ArmRole}
