"""The speed targets, measured on this machine: ``cosim bench --plan targets``.

Each :class:`Target` names a measurement, its threshold and the device it is set on:

- 3-D WCSPH at 1M particles on a CUDA device: >= 80 G pair interactions/s (particle-steps/s times the mean liquid
  neighbours, ~110 at h = 1.5 dx), warp's ``example_sph`` re-sized to the same count measured in the same run beside
  it (:func:`cosim.bench.fluid_throughput.solver_throughput`, the full substep);
- 2-D at 10k particles on a CUDA device: >= 20,000 steps/s (WCSPH and DFSPH with either density iteration measured;
  the figure is the one with the most steps per second, the others in the detail column);
- the 3-D two-arm pour at ~100k particles (64 across the pourer: 111,936) on a CUDA device: at least real time,
  coupling and controllers included (DFSPH with the Jacobi density solve, the GPU's choice for large scenes;
  :func:`cosim.bench.host_overhead.pour_rate`, after a warm-up that compiles and captures);
- the default pour, ``cosim pour --no-log`` as a user runs it (a new process: start-up, scene build, the whole pour,
  the outputs), with the compiled kernels cached by a short run first: <= 60 s wall, the median of
  :attr:`TargetSizes.default_pour_repeats` runs. The target is set for a 2-core CPU; it runs on this machine's CPU,
  whichever it is (the header names it).

On a machine without a CUDA device the CUDA targets are listed as not measured; the CPU target is always measured.
Timings are measured afresh on every run (nothing is cached: a cached time says nothing about this machine now). A
measurement that fails is a row with its one-line error, and the exit status is 1. The fifth target,
DFSPH faster than WCSPH at equal error on the default pour, is the full plan's pour table (``cosim bench``).
"""

from __future__ import annotations

import hashlib
import json
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from cosim.atomic_files import write_text_atomic

GIGA = 1e9


@dataclass(frozen=True)
class TargetSizes:
    """What the measurements run: the targets' sizes by default (tests use small ones, whose numbers mean nothing).

    throughput_3d / throughput_2d: particles of the resting block (:func:`cosim.bench.fluid_throughput.resting_block`).
    steps: WCSPH substeps per timed interval; repeats: timed intervals (medians). pour_3d_across: particles across
    the pourer of the 3-D pour; pour_3d_seconds: its simulated seconds timed after the warm-up.
    default_pour_repeats: timed runs of ``cosim pour --no-log``; default_pour_duration: their simulated s (None: the
    whole default pour, as the target means)."""

    throughput_3d: int = 1_000_000
    throughput_2d: int = 10_000
    steps: int = 20
    repeats: int = 3
    pour_3d_across: int = 64
    pour_3d_seconds: float = 0.5
    default_pour_repeats: int = 3
    default_pour_duration: float | None = None


@dataclass(frozen=True)
class Target:
    """name: the target as the report states it. device: 'cuda' or 'cpu', where it is set. threshold, unit: the
    figure to reach; at_least: True if the figure must be at least the threshold, False if at most."""

    name: str
    device: str
    threshold: float
    unit: str
    at_least: bool


@dataclass(frozen=True)
class Measurement:
    """value: the measured figure in the target's unit (None: not measured or failed); detail: what else the same run
    measured, or why nothing was measured; failed: the measurement raised (detail holds its error); took_s: wall
    seconds the measurement took, set-up and warm-up included (what it costs on a GPU machine held by the minute)."""

    target: Target
    value: float | None
    detail: str
    failed: bool = False
    took_s: float = 0.0

    @property
    def verdict(self) -> str:
        """'met', 'missed, F x' (F: how far the figure is from the threshold, as a ratio), 'failed' or 'not measured'."""
        if self.failed:
            return "failed"
        if self.value is None:
            return "not measured"
        t = self.target
        if (self.value >= t.threshold) if t.at_least else (self.value <= t.threshold):
            return "met"
        ratio = t.threshold / self.value if t.at_least else self.value / t.threshold
        return f"missed, {ratio:.3g} x"

    def to_json(self) -> dict:
        t = self.target
        return {"target": t.name, "device": t.device, "threshold": t.threshold, "unit": t.unit, "at_least": t.at_least,
                "value": self.value, "detail": self.detail, "verdict": self.verdict, "took_s": self.took_s}


THROUGHPUT_3D = Target("3-D WCSPH, 1M particles: full step pair interactions", "cuda", 80.0, "G pair interactions/s", True)
STEPS_2D = Target("2-D, 10k particles: steps per second", "cuda", 20_000.0, "steps/s", True)
POUR_3D = Target("3-D two-arm pour, ~100k particles: real time, coupling and controllers included", "cuda", 1.0,
                 "x real time", True)
DEFAULT_POUR = Target("default pour, `cosim pour --no-log`, compiled kernels cached", "cpu", 60.0, "s wall", False)
TARGETS = (THROUGHPUT_3D, STEPS_2D, POUR_3D, DEFAULT_POUR)


def measure_throughput_3d(device: str, sizes: TargetSizes) -> tuple[float, str]:
    """G pair interactions/s of the 3-D WCSPH full substep (particle-steps/s times mean neighbours), and
    example_sph's beside it."""
    from cosim.bench.fluid_throughput import example_sph_throughput, solver_throughput
    from cosim.fluid.config import FluidConfig, PressureSolver

    rate, _, particles, _, _, neighbours = solver_throughput(sizes.throughput_3d, 3, device, sizes.steps, sizes.repeats, PressureSolver.WCSPH,
                                                             True, 0, FluidConfig.density_iteration)
    theirs, their_neighbours = example_sph_throughput(particles, device, sizes.steps, sizes.repeats)
    return rate * neighbours / GIGA, (
        f"{particles} particles, {neighbours:.0f} neighbours, {rate / GIGA:.3f} G particle-steps/s; warp's example_sph at the same count, "
        f"same run: {theirs * their_neighbours / GIGA:.2f} G pair interactions/s ({theirs / GIGA:.3f} G particle-steps/s, {their_neighbours:.0f} neighbours)"
    )


def measure_steps_2d(device: str, sizes: TargetSizes) -> tuple[float, str]:
    """Substeps per second of the 2-D block, the best of WCSPH and DFSPH with either density iteration (the others
    in the detail, with the simulated seconds per wall second that compare solvers of different time steps)."""
    from cosim.bench.fluid_throughput import solver_throughput
    from cosim.fluid.config import DensityIteration, FluidConfig, PressureSolver

    variants = {"wcsph": (PressureSolver.WCSPH, FluidConfig.density_iteration)}
    variants.update({f"dfsph ({it.value})": (PressureSolver.DFSPH, it) for it in DensityIteration})
    rows = {}
    for name, (solver, iteration) in variants.items():
        rate, sim_rate, particles, _, _, _ = solver_throughput(sizes.throughput_2d, 2, device, sizes.steps, sizes.repeats, solver,
                                                            True, 0, iteration)
        rows[name] = (rate / particles, sim_rate, particles)
    best = max(rows, key=lambda s: rows[s][0])
    parts = [f"{s}: {v[0]:,.0f} steps/s, {v[1]:.4f} simulated s per wall s" for s, v in rows.items()]
    return rows[best][0], f"{rows[best][2]} particles; the figure is {best}'s; " + "; ".join(parts)


def measure_pour_3d(device: str, sizes: TargetSizes) -> tuple[float, str]:
    """Real-time factor of the 3-D pour (DFSPH, Jacobi density solve) after its warm-up."""
    from cosim.bench.host_overhead import pour_rate

    row = pour_rate(device, 3, sizes.pour_3d_across, sizes.pour_3d_seconds, "dfsph", "jacobi")
    return row["real_time_factor"], (
        f"{row['particles']} particles, {row['solver']}, {row['simulated_s']:g} s simulated in {row['wall_s']:.1f} s; per 2 ms "
        f"MuJoCo step: substeps {row['substeps_ms_per_step']:.2f} ms, the rest (host) {row['host_ms_per_step']:.2f} ms"
    )


def _cosim_pour(device: str, out: Path, duration: float | None) -> float:
    """Wall seconds of one ``cosim pour --no-log --quiet --device DEVICE`` in a new process (its outputs into ``out``)."""
    cmd = [sys.executable, "-m", "cosim", "pour", "--no-log", "--quiet", "--device", device, "--out", str(out)]
    cmd += [] if duration is None else ["--duration", f"{duration:g}"]
    start = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        lines = (done.stderr or done.stdout).strip().splitlines()
        raise RuntimeError(f"cosim pour exited with {done.returncode}: {lines[-1] if lines else 'no output'}")
    return wall


def measure_default_pour(device: str, sizes: TargetSizes) -> tuple[float, str]:
    """Median wall seconds of the default pour as a user runs it, after a short run that loads the compiled kernels."""
    with tempfile.TemporaryDirectory(prefix="cosim-targets-") as tmp:
        _cosim_pour(device, Path(tmp) / "warm-up", 0.05)
        walls = [_cosim_pour(device, Path(tmp) / f"run{k}", sizes.default_pour_duration) for k in range(sizes.default_pour_repeats)]
        summary = json.loads((Path(tmp) / "run0" / "summary.json").read_text())
        fingerprint = hashlib.sha256((Path(tmp) / "run0" / "trajectory.csv").read_bytes()).hexdigest()[:12]
    return statistics.median(walls), (
        f"runs: {', '.join(f'{w:.1f}' for w in walls)} s; {summary['sim_time']:.2f} s simulated, "
        f"{1e6 * summary['poured_volume']:.0f} of {1e6 * summary['initial_volume']:.0f} mL poured; "
        f"trajectory.csv sha256 {fingerprint} (the same bits as another machine's if equal)"
    )


MEASURES: dict[Target, Callable[[str, TargetSizes], tuple[float, str]]] = {
    THROUGHPUT_3D: measure_throughput_3d, STEPS_2D: measure_steps_2d, POUR_3D: measure_pour_3d, DEFAULT_POUR: measure_default_pour,
}


def _measure(target: Target, device: str | None, sizes: TargetSizes) -> Measurement:
    if device is None:
        return Measurement(target, None, "no CUDA device on this machine")
    start = time.perf_counter()
    try:
        value, detail = MEASURES[target](device, sizes)
    except Exception as exc:  # a broken measurement is a row of the report, not the end of the others
        message = str(exc).strip().splitlines()
        return Measurement(target, None, f"{type(exc).__name__}: {message[0] if message else ''}", failed=True,
                           took_s=time.perf_counter() - start)
    return Measurement(target, value, detail, took_s=time.perf_counter() - start)


def measure_all(sizes: TargetSizes = TargetSizes(), cuda: str | None = None,
                on_row: Callable[[list[Measurement]], None] | None = None) -> list[Measurement]:
    """Every target: the CUDA ones on ``cuda`` (None: not measured), the CPU one on the CPU. ``on_row`` is called
    with the rows so far after each one (the command rewrites its report, so that a run stopped part-way, e.g. at
    a time limit, leaves the targets it measured)."""
    out: list[Measurement] = []
    for target in TARGETS:
        out.append(_measure(target, cuda if target.device == "cuda" else "cpu", sizes))
        if on_row is not None:
            on_row(out)
    return out


def markdown(measurements: list[Measurement], header: str) -> str:
    """The report: ``header``, then one row per target."""
    lines = [header.rstrip(), "", "| target | on | threshold | measured | verdict | detail | took |", "|---|---|---|---|---|---|---|"]
    for m in measurements:
        t = m.target
        bound = f"{'>=' if t.at_least else '<='} {t.threshold:g} {t.unit}"
        value = "-" if m.value is None else f"{m.value:.4g} {t.unit}"
        took = f"{m.took_s:.0f} s" if m.took_s else "-"
        lines.append(f"| {t.name} | {t.device} | {bound} | {value} | {m.verdict} | {m.detail} | {took} |")
    return "\n".join(lines) + "\n"


def write_report(measurements: list[Measurement], header: str, out: Path) -> str:
    """Write OUT/targets.md and OUT/targets.json (atomically); returns the Markdown."""
    text = markdown(measurements, header)
    write_text_atomic(out / "targets.json", json.dumps([m.to_json() for m in measurements], indent=1) + "\n")
    write_text_atomic(out / "targets.md", text)
    return text
