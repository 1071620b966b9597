"""The default thread count against one thread, on a machine to itself and beside a competing CPU-bound process.

Each run is a new ``cosim pour --duration D --no-log --quiet --threads T`` process, as a user starts it, with T = 0
(the default: one thread per core) and T = 1. Each round runs the two in ABBA order (0, 1; 1, 0; ...) so that a
linear drift of the machine's speed cancels in the medians. The rounds run twice: without another process of this
tool's, then beside one competing process that spins on a core (``while True: pass``) from before the first run to
after the last. The wall time is the pour's own (``summary.json``: the co-simulation loop, without the start-up);
the 1-minute load average before each run says how busy the machine was besides.

    python -m cosim.bench.thread_contention [--duration 2] [--repeats 2] [--docs docs/benchmarks.md]

``--docs`` puts the table between this tool's own markers in that Markdown file (after its first heading the first
time).
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import statistics
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from cosim.bench.fluid_throughput import machine_description
from cosim.bench.options import DURATION
from cosim.bench.report import update_document
from cosim.errors import InputError

BEGIN = "<!-- cosim.bench.thread_contention: generated, begin -->"
END = "<!-- cosim.bench.thread_contention: generated, end -->"
COMPETITOR = "while True: pass"
THREAD_SETTINGS = (0, 1)  # the default (one per core), one thread


@dataclass(frozen=True)
class PourTiming:
    """One pour process: its thread setting, the lanes it ran, its loop's wall time (s), the substeps replayed on
    one thread although it had more lanes, all substeps, and the 1-minute load average before it started."""

    threads: int
    lanes: int
    wall_s: float
    substeps_one_thread: int
    substeps: int
    load_before: float


def time_pour(threads: int, duration: float, folder: Path) -> PourTiming:
    """Run one pour process with ``--threads threads`` for ``duration`` simulated seconds into ``folder``."""
    load = os.getloadavg()[0]
    command = [sys.executable, "-m", "cosim", "pour", "--duration", f"{duration:g}", "--no-log", "--quiet", "--threads", str(threads), "--out", str(folder)]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{shlex.join(command)} failed ({done.returncode}): {done.stderr[-2000:]}")
    summary = json.loads((folder / "summary.json").read_text())
    return PourTiming(
        threads, summary["fluid_threads"], summary["wall_time"], summary["fluid_substeps_one_thread"], summary["sph_steps"], load,
    )


def time_rounds(duration: float, repeats: int, work: Path, tag: str, time_one=time_pour) -> list[PourTiming]:
    """``repeats`` rounds of both thread settings in ABBA order (``time_one``: :func:`time_pour` or a stand-in)."""
    runs = []
    for r in range(repeats):
        order = THREAD_SETTINGS if r % 2 == 0 else THREAD_SETTINGS[::-1]
        for threads in order:
            runs.append(time_one(threads, duration, work / f"{tag}-{r}-{threads}"))
            print(f"  {tag}: --threads {threads}: {runs[-1].wall_s:.1f} s (load {runs[-1].load_before:.2f})", file=sys.stderr, flush=True)
    return runs


def time_beside_competitor(duration: float, repeats: int, work: Path) -> list[PourTiming]:
    """:func:`time_rounds` with one competing CPU-bound process running throughout."""
    competitor = subprocess.Popen([sys.executable, "-c", COMPETITOR])
    try:
        return time_rounds(duration, repeats, work, "competing")
    finally:
        competitor.kill()
        competitor.wait()


def table_row(condition: str, runs: list[PourTiming]) -> str:
    """Markdown row: medians of both settings, their ratio, every run, the load averages, the one-thread share."""
    by = {t: [r for r in runs if r.threads == t] for t in THREAD_SETTINGS}
    med = {t: statistics.median(r.wall_s for r in by[t]) for t in THREAD_SETTINGS}
    walls = lambda rs: ", ".join(f"{r.wall_s:.1f}" for r in rs)  # noqa: E731
    loads = [r.load_before for r in runs]
    lanes = by[0][0].lanes
    one_thread = sum(r.substeps_one_thread for r in by[0]) / sum(r.substeps for r in by[0])
    return (
        f"| {condition} | {min(loads):.1f} to {max(loads):.1f} | {med[0]:.1f} ({walls(by[0])}) | {lanes} | {100 * one_thread:.0f} % | "
        f"{med[1]:.1f} ({walls(by[1])}) | {med[0] / med[1]:.2f} |"
    )


def table(rows: list[str], duration: float, repeats: int, command: str) -> str:
    now = datetime.now(timezone.utc).strftime("%Y-%m-%d")
    return "\n".join([
        f"### Solver threads on a shared CPU ({now})",
        "",
        f"Machine: {machine_description()}. Command: `{command}`. Each row: {repeats} runs of each setting in ABBA order, "
        f"new `cosim pour --duration {duration:g} --no-log --quiet --threads T` processes; the pour loop's wall s "
        "(`summary.json`), median (every run in order). The load average is the machine's 1-minute one before each run: "
        "the runs of this tool and its competitor count in it, so a quiet machine shows about 1, and 2 with the competitor.",
        "",
        "| other processes | load average | default wall s | default threads | default substeps on one thread | --threads 1 wall s | default / one thread |",
        "|---|---|---|---|---|---|---|",
        *rows,
    ]) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m cosim.bench.thread_contention", description=__doc__.split("\n\n")[0])
    ap.add_argument("--duration", type=float, default=2.0, help="simulated s per pour (default 2)")
    ap.add_argument("--repeats", type=int, default=2, help="ABBA rounds per condition (default 2)")
    ap.add_argument("--docs", type=Path, help="Markdown file to put the table into (between this tool's markers)")
    args = ap.parse_args(argv)
    try:
        DURATION.check("--duration", args.duration)
        if not 1 <= args.repeats <= 20:
            raise InputError(f"--repeats: must be in [1, 20], got {args.repeats}")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    command = "python -m cosim.bench.thread_contention " + shlex.join(argv if argv is not None else sys.argv[1:])
    with tempfile.TemporaryDirectory(prefix="cosim-threads-") as tmp:
        work = Path(tmp)
        rows = [
            table_row("none of this tool's", time_rounds(args.duration, args.repeats, work, "quiet")),
            table_row("one competing CPU-bound process", time_beside_competitor(args.duration, args.repeats, work)),
        ]
    text = table(rows, args.duration, args.repeats, command.strip())
    print(text)
    if args.docs:
        update_document(args.docs, text, BEGIN, END)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
