"""Which time-step criterion sets the liquid's substeps in a pour, and what each alternative would cost.

    python -m cosim.bench.time_step_criteria [SCENE] [--duration S] [--threads 1] [--approach-every 10] [--json]

Runs a pour (the default scene, or the scene file SCENE, without its recording) and reads every interval's plan
(:meth:`cosim.fluid.time_step.TimeStepPlanner.limits`, wrapped: the wrapper records and changes nothing, so the run
is the plain pour's to the bit). For each interval: the interval's length, the walls' speed, the last interval's
largest speed and acceleration it was planned from, each criterion's dt (CFL, force, viscous) and the substeps run.
Reported: the substeps per simulated second, the share of intervals and substeps each criterion set, and, on the
same inputs (the flow as it ran, not rerun), the substeps the plan would have taken without the viscous criterion
and with each ``fluid.viscous_time_step``. Every ``--approach-every``-th interval it also measures the liquid's
largest pairwise approach speed at the interval's start, max over pairs within the support 2h of
-min(0, v_ij . r_ij / |r_ij|) (m/s; liquid pairs, by brute force over all pairs: the 2-D pour has about a thousand
particles), against the two bounds the criterion can plan with: 2 x the last interval's largest speed (measured) and
2 x the CFL condition's flow speed (planned). And the DFSPH solves' iterations (divergence, density) of each interval's
last substep, a sample of one substep in three or four: a longer substep leaves its solves more to correct, so the
substeps a criterion saves are not all wall time saved.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import math
import os
import sys
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from cosim.bench.fluid_throughput import machine_description
from cosim.bench.options import DURATION
from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, ViscousTimeStep
from cosim.fluid.solver import FluidSolver
from cosim.fluid.time_step import TimeStepLimits, TimeStepPlanner, split_interval
from cosim.pour_run import prepare
from cosim.pour_scene import LoggingSettings, PourScene, load_scene
from declared_settings.setting import declared


@dataclass(frozen=True)
class PlannedInterval:
    """One interval's plan: its length (s), the walls' speed (m/s), the last interval's largest speed (m/s) and
    acceleration (m/s^2) it was planned from, each criterion's dt and the substeps run."""

    duration: float
    wall_speed: float
    max_speed: float
    max_accel: float
    limits: TimeStepLimits
    substeps: int


@dataclass(frozen=True)
class ApproachSample:
    """The liquid's largest pairwise approach speed (m/s) at an interval's start, with the bounds the criterion can
    plan with there: 2 x the last interval's largest speed, 2 x the CFL condition's flow speed (m/s)."""

    approach: float
    measured_bound: float
    planned_bound: float


def max_approach_speed(positions: np.ndarray, velocities: np.ndarray, support: float) -> float:
    """m/s, the largest approach speed -min(0, v_ij . r_ij / |r_ij|) over the pairs closer than ``support`` (m)."""
    r = positions[:, None, :] - positions[None, :, :]
    v = velocities[:, None, :] - velocities[None, :, :]
    dist = np.sqrt(np.einsum("ijk,ijk->ij", r, r))
    near = (dist < support) & (dist > 0.0)
    closing = -np.einsum("ijk,ijk->ij", v, r)[near] / dist[near]
    return float(max(closing.max(initial=0.0), 0.0))


@dataclass
class Recording:
    """What :func:`recorded_plans` collects: every interval's plan, the approach samples, and each interval's last
    substep's (divergence, density) solve iterations."""

    plans: list[PlannedInterval] = dataclasses.field(default_factory=list)
    samples: list[ApproachSample] = dataclasses.field(default_factory=list)
    iterations: list[tuple[int, int]] = dataclasses.field(default_factory=list)


@contextlib.contextmanager
def recorded_plans(fluid: FluidSolver, approach_every: int) -> Iterator[Recording]:
    """Within the block, every plan of ``fluid``'s intervals, every ``approach_every``-th interval's approach sample
    and each interval's last substep's solve iterations are recorded; the planner is put back on exit."""
    recording = Recording()
    plans, samples = recording.plans, recording.samples
    original_limits, original_plan, original_advance = TimeStepPlanner.limits, fluid.plan_time_step, fluid.advance
    last: list[tuple] = []
    cfg = fluid.config

    def limits(planner: TimeStepPlanner, wall_speed: float, max_speed: float, max_accel: float) -> TimeStepLimits:
        result = original_limits(planner, wall_speed, max_speed, max_accel)
        last.append((wall_speed, max_speed, max_accel, result))
        return result

    def plan(duration: float, wall_speed: float) -> tuple[int, float]:
        if len(plans) % approach_every == 0:
            active = fluid.active_mask()
            approach = max_approach_speed(fluid.positions()[active], fluid.velocities()[active], cfg.support_radius)
            speed = fluid.last_max_speed
            samples.append(ApproachSample(approach, 2.0 * speed, 2.0 * max(cfg.max_expected_speed, speed)))
        n_sub, dt = original_plan(duration, wall_speed)
        (wall, speed, accel, result), = last
        last.clear()
        plans.append(PlannedInterval(duration, wall, speed, accel, result, n_sub))
        return n_sub, dt

    def advance(duration: float):
        interval = original_advance(duration)
        recording.iterations.append(interval.last.solver_iterations)
        return interval

    TimeStepPlanner.limits = limits
    fluid.plan_time_step = plan
    fluid.advance = advance
    try:
        yield recording
    finally:
        TimeStepPlanner.limits = original_limits
        del fluid.plan_time_step, fluid.advance


def substeps_with(plans: list[PlannedInterval], step: Callable[[PlannedInterval], float]) -> int:
    """The substeps the intervals of ``plans`` would take with the step ``step(plan)`` (s), on the same inputs."""
    return sum(split_interval(p.duration, step(p))[0] for p in plans)


def report(recording: Recording, cfg: FluidConfig, substep_wall: float) -> dict:
    """The run's numbers (see the module docstring), JSON-ready."""
    plans, samples = recording.plans, recording.samples
    iterations = np.array(recording.iterations, dtype=float).reshape(-1, 2)
    simulated = sum(p.duration for p in plans)
    substeps = sum(p.substeps for p in plans)
    intervals, by_substeps = Counter(), Counter()
    for p in plans:
        intervals[p.limits.binding] += 1
        by_substeps[p.limits.binding] += p.substeps
    alternatives = {"without the viscous criterion": substeps_with(plans, lambda p: min(p.limits.advection, p.limits.force))}
    for choice in ViscousTimeStep:
        planner = TimeStepPlanner(dataclasses.replace(cfg, viscous_time_step=choice))
        alternatives[f"viscous_time_step = {choice.value}"] = substeps_with(
            plans, lambda p, planner=planner: planner.stable_time_step(p.wall_speed, p.max_speed, p.max_accel))
    approach = np.array([s.approach for s in samples])
    measured = np.array([s.measured_bound for s in samples])
    planned = np.array([s.planned_bound for s in samples])
    quantiles = (50, 90, 99, 100)
    return {
        "config": {"viscous_time_step": cfg.viscous_time_step.value, "max_expected_speed": cfg.max_expected_speed,
                   "smoothing_length": cfg.smoothing_length, "cfl": cfg.cfl, "alpha": cfg.alpha},
        "simulated_s": simulated,
        "intervals": len(plans),
        "substeps": substeps,
        "substeps_per_simulated_s": substeps / simulated if simulated else math.nan,
        "substep_wall_ms": 1e3 * substep_wall / substeps if substeps else math.nan,
        "solve_iterations_per_substep": {"divergence": float(iterations[:, 0].mean()), "density": float(iterations[:, 1].mean())}
        if len(iterations) else {},
        "binding_intervals": dict(intervals),
        "binding_substeps": dict(by_substeps),
        "substeps_on_the_same_inputs": alternatives,
        "approach_samples": len(samples),
        "approach_quantiles": {f"p{q}": {"approach": float(np.percentile(approach, q)), "two_x_measured_speed": float(np.percentile(measured, q)),
                                         "two_x_planned_speed": float(np.percentile(planned, q))} for q in quantiles} if samples else {},
    }


def print_report(out: dict, command: str) -> None:
    print(f"Machine: {machine_description()}, 1-minute load average {os.getloadavg()[0]:.1f} at the end. Command: `{command}`.")
    print(f"{out['simulated_s']:.2f} s simulated in {out['intervals']} intervals, {out['substeps']} substeps "
          f"({out['substeps_per_simulated_s']:.0f} per simulated s, {out['substep_wall_ms']:.3f} ms of wall time each); "
          f"viscous_time_step = {out['config']['viscous_time_step']}.")
    if out["solve_iterations_per_substep"]:
        its = out["solve_iterations_per_substep"]
        print(f"DFSPH solve iterations per substep (each interval's last): divergence {its['divergence']:.2f}, density {its['density']:.2f}.")
    print()
    print("| criterion | intervals it set | substeps it set |")
    print("|---|---|---|")
    for name in TimeStepLimits._fields:
        n, s = out["binding_intervals"].get(name, 0), out["binding_substeps"].get(name, 0)
        print(f"| {name} | {n} ({100 * n / out['intervals']:.1f} %) | {s} ({100 * s / out['substeps']:.1f} %) |")
    print("\n| plan, on the same inputs | substeps | / as run |")
    print("|---|---|---|")
    for name, n in out["substeps_on_the_same_inputs"].items():
        print(f"| {name} | {n} | {n / out['substeps']:.3f} |")
    if out["approach_quantiles"]:
        print(f"\nLargest pairwise approach speed at an interval's start, {out['approach_samples']} samples (m/s):\n")
        print("| quantile over samples | approach | 2 x last interval's largest speed | 2 x the CFL's flow speed |")
        print("|---|---|---|---|")
        for q, row in out["approach_quantiles"].items():
            print(f"| {q} | {row['approach']:.3f} | {row['two_x_measured_speed']:.3f} | {row['two_x_planned_speed']:.3f} |")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m cosim.bench.time_step_criteria", description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", help="a scene file (default: the default scene)")
    ap.add_argument("--duration", type=float, help="simulated s (default: the scene's whole pour)")
    ap.add_argument("--threads", type=int, default=1, help="the liquid solver's CPU threads, 0: one per core (default 1)")
    ap.add_argument("--approach-every", type=int, default=10, help="measure the pairwise approach every N-th interval (default 10)")
    ap.add_argument("--json", action="store_true", help="print the numbers as JSON")
    args = ap.parse_args(argv)
    try:
        if args.duration is not None:
            DURATION.check("--duration", args.duration)
        declared(FluidConfig, "cpu_threads").check("--threads", args.threads)
        if args.approach_every < 1:
            raise InputError(f"--approach-every: must be an integer >= 1, got {args.approach_every}")
        scene = load_scene(args.scene) if args.scene else PourScene()
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    scene = dataclasses.replace(scene, fluid=dataclasses.replace(scene.fluid, cpu_threads=args.threads), logging=LoggingSettings(enabled=False))
    if args.duration is not None:
        scene = dataclasses.replace(scene, coupling=dataclasses.replace(scene.coupling, max_duration=args.duration))
    pour = prepare(scene)
    relaxation_wall = pour.fluid.substep_wall_time
    with recorded_plans(pour.fluid, args.approach_every) as recording:
        pour.run()
    out = report(recording, pour.fluid.config, pour.fluid.substep_wall_time - relaxation_wall)
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        print_report(out, "python -m cosim.bench.time_step_criteria " + " ".join(argv if argv is not None else sys.argv[1:]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
