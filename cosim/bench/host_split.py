"""Where the host's share of each MuJoCo step goes: the wall time of each part of the co-simulation step.

``python -m cosim.bench.host_overhead`` splits a pour's wall time into the liquid's substeps and the rest (the host's
share). This tool splits the rest: it builds the default pour, steps it through a warm-up, then wraps named parts of
the step (the controller, the arms' trajectory generators, the exchange, ``mj_step``, the liquid's host work around
its substeps, the arms' load monitor) and the controller's own parts (the liquid probe, the control law, the pose
filters and smoothers, the IK, the generators' targets, the landing probe) with wall-clock timers around each call,
steps ``--duration`` simulated seconds and prints each part's ms per MuJoCo step. The timers change no result; each
costs about a microsecond a call, so the parts sum to slightly more than they cost unwrapped. Parts nest where the
table says so (the rows named "controller: ..." are inside the controller's row, and so are the generators' targets).
``--calls`` also counts the Python function calls per MuJoCo step over the same stretch of a second pour (cProfile's
count, builtins included): a measure of the host's per-step work that, unlike its time, the machine's load does not
change.

    python -m cosim.bench.host_split [--duration 1] [--threads 1] [--calls]
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import dataclasses
import gc
import math
import os
import pstats
import statistics
import sys
import time
from collections import defaultdict
from collections.abc import Iterator

import mujoco

from cosim.bench.fluid_throughput import machine_description
from cosim.bench.host_overhead import POUR_WARM_UP, time_steps
from cosim.bench.options import DURATION
from cosim.coupling import loop
from cosim.coupling.loop import CoupledPour
from cosim.coupling.pose_filter import PoseFilter, PoseSmoother
from cosim.errors import InputError
from cosim.fluid.config import FluidConfig
from cosim.pour_run import prepare
from declared_settings.setting import declared
from cosim.pour_scene import FluidSettings, LoggingSettings, PourScene

SUBSTEPS = "the liquid's substeps (replay)"
ADVANCE = "liquid: advance (its substeps included)"
CONTROLLER = "controller: "  # the rows inside the controller's period


@contextlib.contextmanager
def timed(owner, name: str, label: str, calls: dict[str, list[float]]) -> Iterator[None]:
    """``owner.name`` (a method of an object, or a function of a module) wrapped so that each call's wall time (s)
    is appended to ``calls[label]``; the original is put back on exit."""
    original = getattr(owner, name)

    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return original(*args, **kwargs)
        finally:
            calls[label].append(time.perf_counter() - start)

    setattr(owner, name, wrapper)
    try:
        yield
    finally:
        setattr(owner, name, original)


def parts(pour: CoupledPour) -> list[tuple[object, str, str]]:
    """(owner, attribute, label) of every timed part of ``pour``'s step."""
    fluid = pour.fluid
    return [
        (pour, "_control", "controller, every control period (measurement, IK, filters, generator targets)"),
        *((generator, "step", "trajectory generators' step") for generator in pour.generators.values()),
        (pour.recorder, "record", "trajectory recorder"),
        (loop, "wrench_at_body_com", "exchange: wrench to the body's centre of mass"),
        (loop, "compensation_torque", "exchange: compensation torque"),
        (loop, "vessel_poses", "exchange: vessel poses from MuJoCo"),
        (fluid, "set_vessel_poses", "exchange: vessel poses to the liquid"),
        (mujoco, "mj_step", "mj_step (the live arms and the load monitor's twin)"),
        (pour.arm_load, "step", "arm load monitor (its twin's mj_step included)"),
        (fluid, "advance", ADVANCE),
        (fluid.lanes, "replay", SUBSTEPS),
        (fluid.scratch.diagnostics, "read", "liquid: diagnostics read back (in advance)"),
        (fluid.energy_account, "update", "liquid: energy account (in advance)"),
        (pour.probe, "measure", CONTROLLER + "liquid probe's measurement (launches and read-backs)"),
        (pour.controller, "step", CONTROLLER + "control law"),
        (PoseFilter, "__call__", CONTROLLER + "pose filters"),
        (PoseSmoother, "__call__", CONTROLLER + "pose smoothers"),
        *((ik, "solve_or_raise", CONTROLLER + "IK") for ik in pour._ik.values()),
        *((generator, "set_target", CONTROLLER + "the arms' generators' targets") for generator in pour.generators.values()),
        (pour.probe, "stream_crossing_x", CONTROLLER + "landing probe (stream crossing the rim)"),
    ]


def default_scene(threads: int) -> PourScene:
    """The default pour on ``threads`` solver threads, without its recording."""
    return PourScene(fluid=dataclasses.replace(FluidSettings(), cpu_threads=threads), logging=LoggingSettings(enabled=False))


def split_pour(scene: PourScene, duration: float) -> tuple[dict[str, list[float]], int, float, float]:
    """``scene`` stepped through the warm-up, then ``duration`` s with its parts timed: (each part's call times, s;
    steps, wall s, substep wall s)."""
    scene = dataclasses.replace(scene, coupling=dataclasses.replace(scene.coupling, max_duration=POUR_WARM_UP + duration))
    pour = prepare(scene)
    time_steps(pour, POUR_WARM_UP)
    calls: dict[str, list[float]] = defaultdict(list)
    with contextlib.ExitStack() as stack:
        for owner, name, label in parts(pour):
            stack.enter_context(timed(owner, name, label, calls))
        split = time_steps(pour, duration)
    return dict(calls), split.steps, split.wall_s, split.substep_s


def calls_per_step(scene: PourScene, duration: float) -> float:
    """Python function calls (cProfile's count, builtins included) per MuJoCo step over ``duration`` s of ``scene``'s
    pour after the warm-up, the garbage of what ran before collected first."""
    scene = dataclasses.replace(scene, coupling=dataclasses.replace(scene.coupling, max_duration=POUR_WARM_UP + duration))
    pour = prepare(scene)
    time_steps(pour, POUR_WARM_UP)
    # earlier pours' garbage finalized now, not inside the count (a finalizer that stops a solver's lane threads
    # waits on them, and its calls depend on the machine's load)
    gc.collect()
    profile, steps = cProfile.Profile(), pour.steps
    profile.enable()
    try:
        time_steps(pour, duration)
    finally:
        profile.disable()
    return pstats.Stats(profile).total_calls / (pour.steps - steps)


def host_work_median(calls: dict[str, list[float]]) -> float:
    """s, the median over the liquid's intervals of each interval's host work: its advance less its substeps' replay
    (one replay an interval once the substeps are captured; NaN where the counts differ)."""
    advances, replays = calls[ADVANCE], calls[SUBSTEPS]
    if len(advances) != len(replays):
        return math.nan
    return statistics.median(a - r for a, r in zip(advances, replays))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m cosim.bench.host_split", description=__doc__.split("\n\n")[0])
    ap.add_argument("--duration", type=float, default=1.0, help="simulated s timed after the warm-up (default 1)")
    ap.add_argument("--threads", type=int, default=1, help="the liquid solver's CPU threads, 0: one per core (default 1)")
    ap.add_argument("--calls", action="store_true", help="also count the Python function calls per MuJoCo step (a second pour)")
    args = ap.parse_args(argv)
    try:
        DURATION.check("--duration", args.duration)
        declared(FluidConfig, "cpu_threads").check("--threads", args.threads)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    calls, steps, wall, substeps = split_pour(default_scene(args.threads), args.duration)
    host = wall - substeps
    command = "python -m cosim.bench.host_split " + " ".join(argv if argv is not None else sys.argv[1:])
    print(f"Machine: {machine_description()}, 1-minute load average {os.getloadavg()[0]:.1f} at the end. Command: `{command.strip()}`.")
    print(f"{steps} MuJoCo steps; wall {1e3 * wall / steps:.3f} ms a step, of which the substeps {1e3 * substeps / steps:.3f} "
          f"and the host {1e3 * host / steps:.3f}. Mean: each part's total time per step; median: its median call times "
          "its calls per step (less the moments the OS gave the core to another process, which a busy machine adds to "
          "whatever part runs then).\n")
    print("| part | calls per step | ms per step, mean | ms per step, median | share of the host's time (mean) |")
    print("|---|---|---|---|---|")
    for label, times in sorted(calls.items(), key=lambda item: -sum(item[1])):
        share = "" if label in (SUBSTEPS, ADVANCE) or label.startswith(CONTROLLER) else f"{100 * sum(times) / host:.0f} %"
        per_step = len(times) / steps
        print(f"| {label} | {per_step:.2f} | {1e3 * sum(times) / steps:.3f} | {1e3 * statistics.median(times) * per_step:.3f} | {share} |")
    advance = sum(calls[ADVANCE]) - sum(calls[SUBSTEPS])
    print(f"| liquid: advance less its substeps (host work) | 1.00 | {1e3 * advance / steps:.3f} | {1e3 * host_work_median(calls):.3f} | "
          f"{100 * advance / host:.0f} % |")
    if args.calls:
        print(f"\nPython function calls per MuJoCo step (cProfile, the same stretch of a second pour): "
              f"{calls_per_step(default_scene(args.threads), args.duration):.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
