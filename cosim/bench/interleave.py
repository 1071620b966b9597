"""Side-by-side timing of the skip-option pairs, for speed-ups smaller than the machine's drift.

``cosim bench`` runs each configuration once, so two rows of a pair may fall into different spells of a shared
machine (identical runs there differ by up to ~25 %). Here each pair's two runs alternate in one process, in ABBA
order over the rounds (skip, full; full, skip; ...) so that a linear drift cancels, and the median wall time per
simulated second of each side gives the speed-up. Errors are not measured here (they are deterministic and in the
bench table); results are not cached.

    python -m cosim.bench.interleave [--repeats 4] [--only NAME ...] [--docs docs/benchmarks.md]

``--docs`` puts the table between this tool's own markers in that Markdown file (after its first heading the
first time).
"""

from __future__ import annotations

import argparse
import shlex
import statistics
import sys
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from cosim.bench.config import BenchConfig
from cosim.bench.plan import SkipOption, build_plan
from cosim.bench.report import update_document
from cosim.bench.run import warm_up
from cosim.bench.runners import run_config
from cosim.errors import InputError
from cosim.bench.fluid_throughput import machine_description

BEGIN = "<!-- cosim.bench.interleave: generated, begin -->"
END = "<!-- cosim.bench.interleave: generated, end -->"


@dataclass(frozen=True)
class PairTiming:
    """Wall s per simulated s of every run of each side (in run order) and the medians' ratio full / skip."""

    option: SkipOption
    skip: tuple[float, ...]
    full: tuple[float, ...]

    @property
    def speed_up(self) -> float:
        return statistics.median(self.full) / statistics.median(self.skip)


def time_pair(option: SkipOption, repeats: int, runner: Callable[[BenchConfig], dict] = run_config) -> PairTiming:
    """Run ``option``'s two configurations ``repeats`` times each, alternating in ABBA order."""
    times: dict[str, list[float]] = {"skip": [], "full": []}
    for r in range(repeats):
        order = ("skip", "full") if r % 2 == 0 else ("full", "skip")
        for side in order:
            result = runner(getattr(option, side))
            times[side].append(result["wall_s"] / result["sim_s"])
    return PairTiming(option, tuple(times["skip"]), tuple(times["full"]))


def table(timings: list[PairTiming], repeats: int, command: str) -> str:
    """Markdown: machine, command, and per pair the medians, the speed-up and every run's time."""
    now = datetime.now(timezone.utc).strftime("%Y-%m-%d")
    lines = [
        f"### Skip options timed side by side ({now})",
        "",
        f"Machine: {machine_description()}. "
        f"Command: `{command}`. Each pair's runs alternate in ABBA order, {repeats} runs a side; wall s per "
        "simulated s, median (every run in order).",
        "",
        "| option | at | skip | full | speed-up (full / skip) |",
        "|---|---|---|---|---|",
    ]
    for t in timings:
        at = f"{t.option.skip.particles_across} across, {t.option.skip.length:g} s"
        runs = lambda xs: f"{statistics.median(xs):.3g} ({', '.join(f'{x:.3g}' for x in xs)})"  # noqa: E731
        lines.append(f"| {t.option.name} (`{t.option.setting}`) | {at} | {runs(t.skip)} | {runs(t.full)} | {t.speed_up:.2f}x |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.bench.interleave", description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=4, help="runs of each side (default 4)")
    parser.add_argument("--only", nargs="*", default=None, help="skip options by name (default: every pair of the full plan)")
    parser.add_argument("--docs", type=Path, help="also put the table into this Markdown file")
    args = parser.parse_args(argv)
    skips = list(build_plan("full").skips)
    names = [s.name for s in skips]
    if args.repeats < 1:
        raise InputError(f"--repeats: must be >= 1, got {args.repeats}")
    for name in args.only or []:
        if name not in names:
            raise InputError(f"--only: {name!r} is not a skip option; one of: {', '.join(names)}")
    chosen = [s for s in skips if args.only is None or s.name in args.only]
    warm_up([c for s in chosen for c in (s.skip, s.full)], run_config)
    timings = []
    for option in chosen:
        print(f"timing {option.name} ...", file=sys.stderr)
        timings.append(time_pair(option, args.repeats))
    command = shlex.join(["python", "-m", "cosim.bench.interleave", *(sys.argv[1:] if argv is None else argv)])
    text = table(timings, args.repeats, command)
    print(text)
    if args.docs is not None:
        update_document(args.docs, text, BEGIN, END)
    return 0


if __name__ == "__main__":
    try:
        raise SystemExit(main())
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        raise SystemExit(2)
