"""A smooth pour motion for both arms, as a jerk-limited joint trajectory (ruckig) through IK of the vessel path.

Task path (pour plane, relative to the vessels' home poses, see :mod:`cosim.robots.planar`): a phase
``s(t)`` rises from 0 to 1 over the first half of ``duration`` and falls back over the second half, each half a
quintic smoothstep ``10 u^3 - 15 u^4 + 6 u^5`` (zero velocity and acceleration at the ends). The pourer tilts by
``s * max_tilt`` about the chosen pivot (bottom middle or lip, fixed in the vessel at home); the catcher translates
by ``s * catcher_dx`` along world x.

Joint trajectory: the path is solved by IK every ``period`` s (each solve seeded with the previous one, so the arm
stays on its home branch), and ruckig, run online with the same cycle, tracks those joint targets (position and
finite-difference velocity) under the arm's joint speed limits and :data:`MAX_ACCELERATION` /
:data:`MAX_JERK`; it ends at rest at home. The ruckig output (position, velocity, acceleration per cycle) is the
trajectory written to CSV.

``python -m cosim.robots.pour_motion --out pour.csv`` writes it; ``cosim replay pour.csv`` measures how the servos
track it.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from enum import Enum

import numpy as np
from ruckig import InputParameter, OutputParameter, Result, Ruckig

from cosim.checks import check_choice, check_positive, check_range
from cosim.errors import InputError
from cosim.io.trajectory_csv import JointTrajectory, write_trajectory_csv
from cosim.robots.planar import PlanarPose, tilt_about_pivot
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole

# Joint acceleration and jerk limits for generated motions, rad/s^2 and rad/s^3. UR publishes no per-joint
# acceleration limit for the UR10e; PolyScope's default joint acceleration is 80 deg/s^2 (1.4 rad/s^2) and its
# maximum 800 deg/s^2. 2.5 rad/s^2 leaves room above the path's own peak (about 0.5 rad/s^2 for 120 deg in 5 s).
MAX_ACCELERATION = 2.5
MAX_JERK = 15.0
# Extra time allowed after the path ends for ruckig to come to rest at home, s.
SETTLE_TIME = 2.0


class Pivot(Enum):
    """Closed choice of the pourer's tilt pivot (a line parallel to world y through this vessel point)."""

    BOTTOM = "bottom"  # the bottom middle, vessel frame origin (the seed's SIM)
    LIP = "lip"  # the pour lip (the seed's CFS)


@dataclass(frozen=True)
class PourMotionSpec:
    """duration: s (1, 120]. max_tilt: rad [0, 2.1]. pivot: :class:`Pivot`. catcher_dx: m [-0.3, 0.3].
    period: s, IK and ruckig cycle (0.001, 0.1]."""

    duration: float = 10.0
    max_tilt: float = math.radians(120.0)
    pivot: Pivot = Pivot.LIP
    catcher_dx: float = 0.15
    period: float = 0.01

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", check_range("pour.duration", self.duration, 1.0, 120.0, "s"))
        object.__setattr__(self, "max_tilt", check_range("pour.max_tilt", self.max_tilt, 0.0, 2.1, "rad"))
        object.__setattr__(self, "pivot", check_choice("pour.pivot", self.pivot, Pivot))
        object.__setattr__(self, "catcher_dx", check_range("pour.catcher_dx", self.catcher_dx, -0.3, 0.3, "m"))
        object.__setattr__(self, "period", check_positive("pour.period", self.period, "s", 0.1))


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


def plan_pour_trajectory(scene: RobotScene, spec: PourMotionSpec = PourMotionSpec()) -> JointTrajectory:
    """The jerk-limited joint trajectory of both arms for ``spec`` (see the module docstring)."""
    roles = list(ArmRole)
    joints = [name for role in roles for name in scene.arms[role].joints]
    n = len(joints)
    seeds = {role: scene.arms[role].home_q for role in roles}

    def path_q(t: float) -> np.ndarray:
        poses = task_poses(scene, spec, t)
        for role in roles:
            seeds[role] = scene.solve_vessel_target(role, poses[role], seeds[role])
        return np.concatenate([seeds[role] for role in roles])

    otg = Ruckig(n, spec.period)
    inp, out = InputParameter(n), OutputParameter(n)
    home = np.concatenate([scene.arms[r].home_q for r in roles])
    inp.current_position, inp.current_velocity, inp.current_acceleration = home, np.zeros(n), np.zeros(n)
    inp.max_velocity = np.concatenate([scene.arms[r].max_joint_speed for r in roles])
    inp.max_acceleration = np.full(n, MAX_ACCELERATION)
    inp.max_jerk = np.full(n, MAX_JERK)
    times, pos, vel, acc = [0.0], [home.copy()], [np.zeros(n)], [np.zeros(n)]
    q_prev = home.copy()
    steps = int(round((spec.duration + SETTLE_TIME) / spec.period))
    for k in range(1, steps + 1):
        t = k * spec.period
        q_target = path_q(min(t, spec.duration))
        inp.target_position = q_target
        inp.target_velocity = (q_target - q_prev) / spec.period if t <= spec.duration else np.zeros(n)
        q_prev = q_target
        result = otg.update(inp, out)
        if result not in (Result.Working, Result.Finished):
            raise InputError(f"pour trajectory: ruckig failed at t={t:.3f} s ({result})")
        times.append(t)
        pos.append(np.array(out.new_position))
        vel.append(np.array(out.new_velocity))
        acc.append(np.array(out.new_acceleration))
        out.pass_to_input(inp)
        if t > spec.duration and result == Result.Finished:
            break
    return JointTrajectory(np.array(times), tuple(joints), np.array(pos), np.array(vel), np.array(acc))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Write a smooth two-arm pour motion as a trajectory CSV.")
    parser.add_argument("--out", required=True, help="CSV file to write")
    parser.add_argument("--duration", type=float, default=10.0, help="s (default 10)")
    parser.add_argument("--tilt-deg", type=float, default=120.0, help="peak tilt, deg (default 120)")
    parser.add_argument("--pivot", choices=[p.value for p in Pivot], default=Pivot.LIP.value)
    parser.add_argument("--catcher-dx", type=float, default=0.15, help="catcher travel at peak, m (default 0.15)")
    parser.add_argument("--model", default=None, help="scene MJCF (default: the project's scene)")
    args = parser.parse_args(argv)
    try:
        spec = PourMotionSpec(args.duration, math.radians(args.tilt_deg), Pivot(args.pivot), args.catcher_dx)
        trajectory = plan_pour_trajectory(RobotScene.load(args.model), spec)
        write_trajectory_csv(args.out, trajectory)
    except InputError as exc:
        print(f"pour_motion: error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {args.out}: {trajectory.time.size} samples, {trajectory.duration:.2f} s, {len(trajectory.joint_names)} joints")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
