"""A sweep's results: sweep.csv, the outcomes plotted against each axis, and the trajectory library.

``sweep.csv``: one row per pour, in the sweep's order: its axes, its status ('done', 'failed', 'not run'), the
failure's kind and line, then from its summary.json the poured, caught and spilled volumes (mL), a partial pour's
target and its error (poured - target, mL; empty for a pour until empty), the landing error (median |measured -
predicted| x of the stream at the catcher's rim during CFS, mm; :func:`cosim.coupling.landing.landing_accuracy`),
the pour's simulation wall time (s, setup and kernel loading left out) and its run folder (relative to the sweep's
output). ``plots/<axis>.png``: each outcome of the done pours against that axis. ``library.json``: the trajectory
library, each done pour's axes -> its trajectory files (paths relative to the library), for a cell to pick the
trajectory of its case (e.g. its fill level).
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cosim.atomic_files import atomic_path, write_text_atomic

if TYPE_CHECKING:
    from cosim.sweep.plan import PlannedPour, SweepPlan

ML = 1e6  # mL per m^3
MM = 1e3  # mm per m
# Outcome columns (the CSV's and the plots'): name -> (label, summary.json -> value).
OUTCOMES = {
    "poured_mL": ("poured (mL)", lambda s: s["poured_volume"] * ML),
    "caught_mL": ("caught (mL)", lambda s: s["caught_volume"] * ML),
    "spilled_mL": ("spilled (mL)", lambda s: s["spilled_volume"] * ML),
    "target_mL": ("partial-pour target (mL)", lambda s: None if s["target_volume"] is None else s["target_volume"] * ML),
    "target_error_mL": ("poured - target (mL)", lambda s: None if s["target_error"] is None else s["target_error"] * ML),
    "landing_error_mm": ("landing error, median (mm)",
                         lambda s: s["landing"]["median_abs_error"] * MM if s["landing"].get("samples") else None),
    "wall_time_s": ("simulation wall time (s)", lambda s: s["wall_time"]),
}
TRAJECTORY_FILES = {"csv": "trajectory.csv", "json": "trajectory.json", "mcap": "trajectory.mcap"}
CSV_NAME, LIBRARY_NAME, PLOTS = "sweep.csv", "library.json", "plots"


def _summary(plan: SweepPlan, pour: PlannedPour) -> dict | None:
    if plan.status(pour) != "done":
        return None
    return json.loads((plan.store.run_folder(pour.key) / "summary.json").read_text())


def pour_rows(plan: SweepPlan) -> list[dict[str, Any]]:
    """One row per pour (module docstring), values as numbers (None where there is none)."""
    rows = []
    for pour in plan.pours:
        summary = _summary(plan, pour)
        failure = plan.failure(pour) or {}
        row = dict(pour.point.axes)
        row.update(status=plan.status(pour), failure=failure.get("kind"), error=failure.get("error"))
        row.update({name: (get(summary) if summary else None) for name, (_, get) in OUTCOMES.items()})
        row["run_folder"] = str(plan.store.run_folder(pour.key).relative_to(plan.store.root)) if summary else None
        rows.append(row)
    return rows


def write_csv(plan: SweepPlan, rows: list[dict[str, Any]]) -> Path:
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows([{k: "" if v is None else v for k, v in row.items()} for row in rows])
    path = plan.store.root / CSV_NAME
    write_text_atomic(path, text.getvalue())
    return path


def write_library(plan: SweepPlan) -> Path:
    """library.json: the axes' names, the code id, and per done pour its axes and trajectory files."""
    entries = []
    for pour in plan.pours:
        if plan.status(pour) != "done":
            continue
        folder = plan.store.run_folder(pour.key).relative_to(plan.store.root)
        entries.append({"axes": pour.point.axes, "run_folder": folder.as_posix(),
                        "trajectory": {kind: (folder / name).as_posix() for kind, name in TRAJECTORY_FILES.items()}})
    library = {"axes": [a.key for a in plan.spec.axes], "code": plan.code, "pours": entries}
    path = plan.store.root / LIBRARY_NAME
    write_text_atomic(path, json.dumps(library, indent=2) + "\n")
    return path


def write_plots(plan: SweepPlan, rows: list[dict[str, Any]]) -> list[Path]:
    """plots/<axis>.png per axis: every outcome that any done pour has, against the axis (one point per pour)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    done = [r for r in rows if r["status"] == "done"]
    outcomes = [name for name in OUTCOMES if any(r[name] is not None for r in done)]
    if not done or not outcomes:
        return []
    paths = []
    for axis in plan.spec.axes:
        fig, panels = plt.subplots(len(outcomes), 1, figsize=(6.0, 1.9 * len(outcomes)), sharex=True, squeeze=False)
        for panel, name in zip(panels[:, 0], outcomes):
            points = [(r[axis.key], r[name]) for r in done if r[name] is not None]
            panel.plot([x for x, _ in points], [y for _, y in points], "o")  # text values: one category each
            panel.set_ylabel(OUTCOMES[name][0], fontsize=8)
            panel.grid(alpha=0.3)
        panels[-1, 0].set_xlabel(axis.key)
        fig.suptitle(f"{plan.spec.name}: {len(done)} pours against {axis.key}", fontsize=10)
        fig.tight_layout()
        path = plan.store.root / PLOTS / f"{axis.key}.png"
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=100, format="png")
        plt.close(fig)
        paths.append(path)
    return paths


def write_report(plan: SweepPlan) -> dict[str, Any]:
    """Write sweep.csv, the plots and library.json; returns their paths and the pours' counts by status."""
    rows = pour_rows(plan)
    counts = {status: sum(r["status"] == status for r in rows) for status in ("done", "failed", "not run")}
    return {"csv": write_csv(plan, rows), "library": write_library(plan), "plots": write_plots(plan, rows), "counts": counts}
