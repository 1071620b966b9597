"""A smooth pour motion for both arms, as a joint trajectory through IK of a quintic-timed vessel path.

Task path (pour plane, relative to the vessels' home poses, see :mod:`cosim.robots.planar`): a phase ``s(t)``
rises from 0 to 1 over the first half of ``duration`` and falls back over the second half, each half a quintic
smoothstep ``10 u^3 - 15 u^4 + 6 u^5`` (zero velocity and acceleration at the ends and at the turn-around). The
pourer tilts by ``s * max_tilt`` about the chosen pivot (bottom middle or lip, fixed in the vessel at home); the
catcher translates by ``s * catcher_dx`` along world x.

Joint trajectory: the path is solved by IK every ``period`` s to :data:`PLANNING_TOLERANCE` (each solve seeded with
the previous one, so the arms stay on their home branches); velocities and accelerations are central differences of
those samples (zero at both ends, where the path is at rest). The result is checked against the arms' joint speed
limits and :data:`MAX_ACCELERATION` / :data:`MAX_JERK` (jerk by differencing the accelerations); a motion that
exceeds them is refused with an ``InputError`` naming the joint, so every trajectory written is jerk-limited.

``python -m cosim.tools.pour_motion --out pour.csv`` writes it; ``cosim replay pour.csv`` measures how the servos
track it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from cosim.errors import InputError
from cosim.robots.ik import IKSettings
from cosim.robots.planar import PlanarPose, tilt_about_pivot
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.joint_trajectory import JointTrajectory
from declared_settings.setting import check_settings, documented, setting

# Joint acceleration and jerk limits for generated motions, rad/s^2 and rad/s^3. UR publishes no per-joint
# acceleration limit for the UR10e; PolyScope's default joint acceleration is 80 deg/s^2 (1.4 rad/s^2) and its
# maximum 800 deg/s^2. 2.5 rad/s^2 and 15 rad/s^3 leave room above a 120 deg tilt in 5 s (about 1 rad/s^2).
MAX_ACCELERATION = 2.5
MAX_JERK = 15.0
# IK tolerance of the path samples (m and rad): far below the differencing step so derivatives are not noise.
PLANNING_TOLERANCE = 1e-10


class Pivot(Enum):
    """Closed choice of the pourer's tilt pivot (a line parallel to world y through this vessel point)."""

    BOTTOM = "bottom"  # bottom middle, vessel frame origin (slosh induction's pivot in Camporredondo et al. 2019)
    LIP = "lip"  # the pour lip (their pivot in the constant-flow stage)


SCRIPTED_POUR = "scripted pour"


@documented
@dataclass(frozen=True)
class PourMotionSpec:
    """A scripted pour: the pourer tilts up and back about a pivot while the catcher moves under the stream."""

    duration: float = setting(10.0, SCRIPTED_POUR, "Length of the whole motion, tilt up and back.", "s", 1.0, 120.0)
    max_tilt: float = setting(math.radians(120.0), SCRIPTED_POUR, "The pourer's largest tilt, at half the duration.",
                              "rad", 0.0, 2.1)
    pivot: Pivot = setting(Pivot.LIP, SCRIPTED_POUR, "The tilt's pivot: 'lip' (the pour lip) or 'bottom' (the bottom "
                           "middle).")
    catcher_dx: float = setting(0.15, SCRIPTED_POUR, "How far the catcher moves along the pour direction at the "
                                "largest tilt.", "m", -0.3, 0.3)
    period: float = setting(0.01, SCRIPTED_POUR, "Sample period of the trajectory.", "s", 0.0, 0.1, lo_open=True)

    def __post_init__(self) -> None:
        check_settings(self, "pour")


def phase(t: float, duration: float) -> float:
    """Pour phase s in [0, 1] at time t (s): quintic smoothstep up over the first half, down over the second."""
    half = 0.5 * duration
    u = min(max(t / half if t <= half else (duration - t) / half, 0.0), 1.0)
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


def task_poses(scene: RobotScene, spec: PourMotionSpec, t: float) -> dict[ArmRole, PlanarPose]:
    """Vessel targets (relative to home) of both arms at time t (s)."""
    s = phase(t, spec.duration)
    pourer = scene.arms[ArmRole.POUR]
    pivot = pourer.vessel.lip_local if spec.pivot is Pivot.LIP else np.zeros(3)
    return {
        ArmRole.POUR: tilt_about_pivot(pourer.home_quat, pivot, s * spec.max_tilt),
        ArmRole.CATCH: PlanarPose(dx=s * spec.catcher_dx),
    }


def _check_limits(trajectory: JointTrajectory, max_speed: np.ndarray, period: float) -> None:
    jerk = np.diff(trajectory.accelerations, axis=0) / period
    for quantity, values, limit, unit in (
        ("speed", trajectory.velocities, max_speed, "rad/s"),
        ("acceleration", trajectory.accelerations, np.full(max_speed.size, MAX_ACCELERATION), "rad/s^2"),
        ("jerk", jerk, np.full(max_speed.size, MAX_JERK), "rad/s^3"),
    ):
        peak = np.max(np.abs(values), axis=0)
        worst = int(np.argmax(peak / limit))
        if peak[worst] > limit[worst]:
            raise InputError(
                f"pour trajectory: joint {trajectory.joint_names[worst]} needs {quantity} {peak[worst]:.3g} {unit}, "
                f"above its limit {limit[worst]:.3g} {unit}; use a longer duration"
            )


def plan_pour_trajectory(scene: RobotScene, spec: PourMotionSpec = PourMotionSpec()) -> JointTrajectory:
    """The joint trajectory of both arms for ``spec`` (see the module docstring); ``InputError`` if a target is
    unreachable or the motion exceeds the joint limits."""
    roles = list(ArmRole)
    solvers = {role: scene.ik(role, IKSettings(PLANNING_TOLERANCE, PLANNING_TOLERANCE, 100, stall_iterations=20)) for role in roles}
    seeds = {role: scene.arms[role].home_q for role in roles}
    times = np.linspace(0.0, spec.duration, int(round(spec.duration / spec.period)) + 1)
    samples = []
    for t in times:
        poses = task_poses(scene, spec, float(t))
        for role in roles:
            pos, quat = scene.vessel_target(role, poses[role])
            label = f"{scene.arms[role].vessel.name} path at t={t:.2f} s"
            seeds[role] = solvers[role].solve_or_raise(pos, quat, seeds[role], label)
        samples.append(np.concatenate([seeds[role] for role in roles]))
    q = np.array(samples)
    h = times[1] - times[0]
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    qd[1:-1] = (q[2:] - q[:-2]) / (2.0 * h)
    qdd[1:-1] = (q[2:] - 2.0 * q[1:-1] + q[:-2]) / (h * h)
    joints = tuple(name for role in roles for name in scene.arms[role].joints)
    trajectory = JointTrajectory(times, joints, q, qd, qdd)
    _check_limits(trajectory, np.concatenate([scene.arms[r].max_joint_speed for r in roles]), h)
    return trajectory
