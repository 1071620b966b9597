"""A checked joint trajectory from scripted vessel targets: IK at the control rate, ruckig, sampling (no simulation).

:func:`generate_scripted` takes, per arm, a sequence of vessel targets (:class:`PlanarPose` relative to home, target
``k`` for time ``k * target_period``, the first where the arm starts at rest), solves each by IK (seeded with the
previous solution, to :data:`SCRIPT_IK` tolerances), streams the joint targets into one :class:`TrajectoryGenerator`
per arm as the coupling does (``set_target`` every ``target_period``, ``step`` every MuJoCo time step), then brings
both arms to rest on the last target, samples at ``sample_rate_hz`` and checks the result (:func:`check_trajectory`).

The generator follows its target stream :data:`cosim.trajectory.generator.STREAM_DELAY_PERIODS` periods late (on the
B-spline through the targets), so target ``k`` is sent that many periods before its time: the script is known in
advance, and the trajectory follows it without lag.

``python -m cosim.tools.scripted_pour --out DIR`` writes the files of such a trajectory.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from cosim.errors import InputError, SimulationError
from cosim.robots.ik import IKSettings
from cosim.robots.planar import PlanarPose
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.checks import check_trajectory
from cosim.trajectory.generator import STREAM_DELAY_PERIODS, GeneratorSettings, TrajectoryGenerator
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.limits import ArmLimits, scene_limits
from cosim.trajectory.pour_motion import PourMotionSpec, task_poses
from cosim.trajectory.recorder import TrajectoryRecorder
from cosim.trajectory.sampling import DEFAULT_SAMPLE_RATE_HZ

# IK tolerances (m, rad) of the scripted targets. With the scene's default vessel-target tolerance (1e-5) the joint
# targets carry up to 2e-5 rad of solver noise, which differencing at 100 Hz turns into 0.2 rad/s^2 of acceleration
# noise that the generator must follow; converged targets keep the trajectory as smooth as the path.
SCRIPT_IK = IKSettings(position_tolerance=1e-10, rotation_tolerance=1e-10, max_iterations=100, stall_iterations=20)
# s: longest time the arms may take to come to rest on the last target after the script ends.
MAX_SETTLE_TIME = 5.0


@dataclass(frozen=True)
class ScriptedRun:
    """Result of :func:`generate_scripted`.

    trajectory: the checked samples of both arms (columns in :class:`ArmRole` order).
    limits: the arms' limits, column order. sample_rate_hz: Hz.
    targets: per arm, (K, n) rad, the IK joint target for ``k * target_period`` (sent
    :data:`STREAM_DELAY_PERIODS` periods earlier).
    clamped_targets: per joint, targets clamped onto the joint range.
    late_targets, max_target_error: per arm, :attr:`TrajectoryGenerator.late_targets` and
    :attr:`TrajectoryGenerator.max_target_error` (rad).
    """

    trajectory: JointTrajectory
    limits: tuple[ArmLimits, ...]
    sample_rate_hz: float
    targets: dict[ArmRole, np.ndarray]
    clamped_targets: dict[str, int]
    late_targets: dict[ArmRole, int]
    max_target_error: dict[ArmRole, float]


def generate_scripted(
    scene: RobotScene,
    poses: Mapping[ArmRole, Sequence[PlanarPose]],
    target_period: float = 0.01,
    sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ,
    limits: Mapping[ArmRole, ArmLimits] | None = None,
) -> ScriptedRun:
    """The checked joint trajectory of both arms following ``poses`` (see the module docstring).

    poses: per arm, K >= 1 vessel targets relative to home, one per ``target_period`` s (a multiple of the scene's
    time step). limits: per arm (default :func:`scene_limits`). Raises ``InputError`` for an unreachable target or bad
    arguments, :class:`UnsafeTrajectoryError` if the result breaks a limit.
    """
    roles = list(ArmRole)
    limits = dict(limits) if limits is not None else scene_limits(scene)
    counts = {len(poses[r]) for r in roles}
    if len(counts) != 1 or 0 in counts:
        raise InputError(f"scripted poses: both arms need the same non-zero number of targets, got {sorted(counts)}")
    cycle = float(scene.model.opt.timestep)
    per_target = round(target_period / cycle)
    if per_target < 1 or abs(per_target * cycle - target_period) > 1e-9:
        raise InputError(f"scripted target_period: must be a multiple of the time step {cycle:g} s, got {target_period:g} s")
    settings = GeneratorSettings(cycle_time=cycle, control_period=per_target * cycle, stop_beyond_velocity_limit=True)

    solvers = {r: scene.ik(r, SCRIPT_IK) for r in roles}
    targets: dict[ArmRole, list[np.ndarray]] = {r: [] for r in roles}
    seeds = {r: scene.arms[r].home_q.copy() for r in roles}

    def solve(role: ArmRole, k: int) -> np.ndarray:
        pose = poses[role][k]
        pos, quat = scene.vessel_target(role, pose)
        label = f"{scene.arms[role].vessel.name} scripted target {k} (dx={pose.dx:.3f} m, dz={pose.dz:.3f} m, tilt={math.degrees(pose.theta):.1f} deg)"
        seeds[role] = solvers[role].solve_or_raise(pos, quat, seeds[role], label)
        targets[role].append(seeds[role])
        return seeds[role]

    count = counts.pop()
    for k in range(count):
        for r in roles:
            solve(r, k)
    generators = {r: TrajectoryGenerator(limits[r], targets[r][0], settings) for r in roles}
    recorder = TrajectoryRecorder([generators[r] for r in roles], sample_rate_hz)

    def advance(steps: int) -> None:
        for _ in range(steps):
            for g in generators.values():
                g.step()
            recorder.record()

    for k in range(count):
        for r in roles:
            generators[r].set_target(targets[r][min(k + STREAM_DELAY_PERIODS, count - 1)])
        advance(per_target)
    for r in roles:
        zero = np.zeros(len(limits[r].joints))
        generators[r].set_target(targets[r][-1], zero, zero)
    for _ in range(int(math.ceil(MAX_SETTLE_TIME / cycle))):
        if all(g.at_rest for g in generators.values()):
            break
        advance(1)
    else:
        raise SimulationError(f"scripted trajectory: the arms did not come to rest within {MAX_SETTLE_TIME} s of the end")
    trajectory = recorder.trajectory()
    check_trajectory(trajectory, recorder.limits)
    clamped = {name: c for g in generators.values() for name, c in g.clamped_targets.items()}
    return ScriptedRun(
        trajectory=trajectory,
        limits=recorder.limits,
        sample_rate_hz=recorder.sample_rate_hz,
        targets={r: np.array(v) for r, v in targets.items()},
        clamped_targets=clamped,
        late_targets={r: g.late_targets for r, g in generators.items()},
        max_target_error={r: g.max_target_error for r, g in generators.items()},
    )


def pour_poses(scene: RobotScene, spec: PourMotionSpec, target_period: float = 0.01) -> dict[ArmRole, list[PlanarPose]]:
    """The scripted pour of :mod:`cosim.trajectory.pour_motion` as targets every ``target_period`` s from 0 to its end."""
    count = int(round(spec.duration / target_period)) + 1
    samples = [task_poses(scene, spec, k * target_period) for k in range(count)]
    return {role: [s[role] for s in samples] for role in ArmRole}


def pour_path(scene: RobotScene, spec: PourMotionSpec) -> dict[ArmRole, Callable[[float], PlanarPose]]:
    """Per arm, the pour's vessel path ``t -> PlanarPose`` (at rest before 0 and after the end)."""
    return {role: (lambda t, role=role: task_poses(scene, spec, min(max(t, 0.0), spec.duration))[role]) for role in ArmRole}
