"""The slosh-induction study's table from sweep outputs: what SIM, its PID and the hand-over do to a pour.

    python -m cosim.bench.slosh_study SWEEP_OUT [SWEEP_OUT ...] [--out FILE.md]

Reads each sweep output's sweep.csv (``cosim sweep``, e.g. examples/sim_study.toml and examples/approach_study.toml)
and, for every pour that ran, its summary.json and series.csv, and prints one Markdown row per pour: its axes, the
spill (% of what it poured), when the outflow became steady (s after the pour's start), the spread of h_q in CFS
(median and interquartile range after the steady outflow, mm, over the samples with a surface to measure, the probe
reporting -inner height for a vessel too empty for one, until 90 % of what the pour poured has left: the rest drains
near the deepest tilt with the head at a fraction of a millimetre, for as long as the stall rule lets it, and would
be most of the samples), how long t1 (the hold) lasted, how long t2 lasted and why it ended, the slosh angle's largest
|sigma| over the first and the last half slosh period of t2 (rad), and when the pour was done (s).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
from pathlib import Path

import numpy as np

from controllers.config import CFS_MAX_HEAD
from cosim.atomic_files import write_text_atomic

HEAD_WINDOW_FRACTION = 0.9  # of the poured volume: h_q in CFS is read until this much has left
HALF_PERIOD_SAMPLES = 25  # control steps (10 ms) in half a slosh period of the paper's vessel (0.50 s period)
COLUMNS = ("spill (% of poured)", "steady outflow (s)", "h_q in CFS to 90 % poured: median, IQR (mm)", "t1 (s)",
           "t2 (s)", "t2 ended", "max sigma, t2 start (rad)", "max sigma, t2 end (rad)", "done at (s)")


def pour_row(folder: Path) -> list[str]:
    """The table's cells for one run folder (the COLUMNS)."""
    summary = json.loads((folder / "summary.json").read_text())
    with open(folder / "series.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["t"]) for r in rows])
    phase = np.array([r["phase"] for r in rows])
    sigma = np.array([float(r["theta1"]) - float(r["tilt"]) for r in rows])
    h_q = np.array([float(r["h_q"]) for r in rows])
    poured = summary["poured_volume"]
    spill = 100.0 * summary["spilled_volume"] / poured if poured > 0 else math.nan
    steady = summary["outflow"].get("steady_outflow")
    steady = math.nan if steady is None else steady
    has_surface = h_q > -CFS_MAX_HEAD  # the probe's "no surface" is -inner height; CFS heads lie within +-CFS_MAX_HEAD
    holding = np.array([float(r["poured_volume"]) for r in rows]) < HEAD_WINDOW_FRACTION * poured
    cfs = (phase == "cfs") & (t >= steady + summary["scene"]["coupling"]["start_delay"]) & has_surface & holding
    hold = np.flatnonzero(phase == "sim_hold")
    damp = np.flatnonzero(phase == "sim_damp")
    ended = next((tr["reason"].split(":")[0].split(",")[0] for tr in summary["transitions"] if tr["from"] == "sim_damp"), "")
    done = next((p["start"] for p in summary["phases"] if p["phase"] == "done"), math.nan)
    cells = [
        f"{spill:.2f}",
        "-" if math.isnan(steady) else f"{steady:.2f}",
        "{:.1f}, {:.1f}".format(1e3 * np.median(h_q[cfs]), 1e3 * np.subtract(*np.percentile(h_q[cfs], [75, 25])))
        if cfs.any() else "-",
        f"{t[hold[-1]] - t[hold[0]] + 0.01:.2f}" if hold.size else "-",
        f"{t[damp[-1]] - t[damp[0]] + 0.01:.2f}" if damp.size else "-",
        ended or "-",
        f"{np.max(np.abs(sigma[damp[:HALF_PERIOD_SAMPLES]])):.3f}" if damp.size else "-",
        f"{np.max(np.abs(sigma[damp[-HALF_PERIOD_SAMPLES:]])):.3f}" if damp.size else "-",
        f"{done:.2f}",
    ]
    return cells


def study_table(outputs: list[Path]) -> str:
    """The Markdown table over every pour of the sweep ``outputs`` (failed ones with their error)."""
    lines = []
    for out in outputs:
        with open(out / "sweep.csv", newline="") as f:
            pours = list(csv.DictReader(f))
        columns = list(pours[0])
        axes = columns[: columns.index("status")]  # sweep.csv: the axes first, then the status and outcomes
        lines += [f"| {' | '.join(axes + list(COLUMNS))} |", "|" + "---|" * (len(axes) + len(COLUMNS))]
        for pour in pours:
            values = [pour[a] for a in axes]
            if pour["status"] == "done":
                values += pour_row(out / pour["run_folder"])
            else:
                values += [f"{pour['status']}: {pour['error']}"] + [""] * (len(COLUMNS) - 1)
            lines.append(f"| {' | '.join(values)} |")
        lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.bench.slosh_study", description=__doc__.split("\n")[0])
    parser.add_argument("outputs", nargs="+", type=Path, help="sweep output folders (each with its sweep.csv)")
    parser.add_argument("--out", type=Path, default=None, help="also write the table to this Markdown file")
    args = parser.parse_args(argv)
    table = study_table(args.outputs)
    print(table)
    if args.out is not None:
        write_text_atomic(args.out, table + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
