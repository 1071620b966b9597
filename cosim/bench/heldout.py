"""Held-out pours: spill, landing error and partial-pour error of every scene of a folder, against the acceptance
thresholds, PASS or FAIL per row.

The held-out scenes (``examples/heldout/``) are pours no constant of the solver or the controller is chosen on:
they check that what was tuned elsewhere (the validation cases) holds on pours nobody tuned on. Each scene runs as
``cosim pour SCENE --no-log --threads 1`` would (the liquid's results are the same on any number of threads), one
pour at a time. The pours are kept as a sweep keeps them (:class:`cosim.sweep.store.SweepStore`): one run folder per scene
under a key that hashes the scene and the simulation code (:func:`cosim.bench.cache.code_version` of the pour: the
bench and CLI code left out), so a rerun reports what is done and runs only what is missing or failed.

What each row reports, from the pour's summary.json (the columns of :data:`cosim.sweep.report.OUTCOMES`):

- spill: the volume neither in the pourer nor in the catcher at the end, in mL and in % of the poured volume
  (initial - left in the pourer); passes at <= :data:`SPILL_LIMIT_PERCENT`.
- landing: the median over the CFS control steps of |measured - predicted| landing x, where the stream crosses the
  catcher's rim plane against where the catcher controller predicted it (:func:`cosim.coupling.landing.landing_accuracy`),
  in mm; passes at <= :data:`LANDING_LIMIT_MM`. A pour without a landing sample fails.
- partial pour (a scene with ``liquid.pour_fraction`` < 1): |poured - target| in % of the target volume; passes at
  <= :data:`PARTIAL_LIMIT_PERCENT`. A pour until empty has no target: not applicable.

A row passes when each of its criteria does; a pour that failed (a refused scene, an instability) fails its row.
"""

from __future__ import annotations

import shutil
import sys
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cosim.errors import InputError, SimulationError
from cosim.sweep.report import OUTCOMES

if TYPE_CHECKING:
    from cosim.pour_scene import PourScene
    from cosim.sweep.store import SweepStore

SPILL_LIMIT_PERCENT = 1.0  # % of the poured volume
LANDING_LIMIT_MM = 5.0  # mm, median landing error
PARTIAL_LIMIT_PERCENT = 3.0  # % of the partial pour's target volume
DEFAULT_SCENES = Path("examples") / "heldout"


@dataclass(frozen=True)
class HeldoutPour:
    """path: the scene file.   scene: its scene as the bench runs it (no recording, one thread).
    key: its store key (the scene and the code version)."""

    path: Path
    scene: PourScene
    key: str


def bench_scene(path: Path) -> PourScene:
    """The scene of ``path`` as ``cosim pour PATH --no-log --threads 1`` runs it."""
    from cosim.pour_scene import load_scene

    scene = load_scene(path).named_after(path)
    return replace(scene, logging=replace(scene.logging, enabled=False), fluid=replace(scene.fluid, cpu_threads=1))


def load_pours(folder: Path, code: str) -> list[HeldoutPour]:
    """Every ``*.toml`` scene of ``folder``, in name order, keyed for the code version ``code``; InputError for a
    folder without scenes or a scene file that does not parse."""
    from cosim.sweep.store import pour_key

    paths = sorted(Path(folder).glob("*.toml"))
    if not paths:
        raise InputError(f"--scenes: no scene files (*.toml) in {folder}")
    pours = []
    for path in paths:
        scene = bench_scene(path)
        pours.append(HeldoutPour(path, scene, pour_key(scene, code)))
    return pours


def run_missing(pours: list[HeldoutPour], store: SweepStore, fresh: bool = False, progress: bool = True) -> int:
    """Run, one at a time, each pour without a complete run folder (every pour with ``fresh``); a pour refused or
    broken is recorded as failed and the others go on. Returns how many pours ran."""
    from tqdm import tqdm

    from controllers.errors import ControllerInputError, MeasurementError
    from cosim.pour_run import run_pour
    from cosim.sweep.runner import failure

    todo = [p for p in pours if fresh or not store.is_complete(p.key)]
    print(f"held-out pours: {len(pours)} scenes, {len(pours) - len(todo)} done, {len(todo)} to run", file=sys.stderr)
    bar = tqdm(todo, unit="pour", disable=not progress, file=sys.stderr, mininterval=1.0)
    for pour in bar:
        bar.set_description_str(pour.scene.run_name)
        store.remove_partial(pour.key)
        shutil.rmtree(store.run_folder(pour.key), ignore_errors=True)  # only with fresh: otherwise it is not there
        try:
            run_pour(pour.scene, store.run_folder(pour.key), progress=False)
        except (InputError, SimulationError, ControllerInputError, MeasurementError) as exc:
            store.record_failure(pour.key, {"scene": str(pour.path), **failure(exc)})
        else:
            store.clear_failure(pour.key)
    bar.close()
    return len(todo)


@dataclass(frozen=True)
class Criterion:
    """One acceptance check of a row.   value: the measured number (None where there is none).
    limit: the threshold it must not exceed.   applies: False where the scene has nothing to check (a pour until
    empty has no partial-pour target)."""

    value: float | None
    limit: float
    applies: bool = True

    @property
    def passed(self) -> bool:
        return not self.applies or (self.value is not None and self.value <= self.limit)


def criteria(summary: dict) -> dict[str, Criterion]:
    """The row's acceptance checks from a pour's summary.json (module docstring)."""
    poured = OUTCOMES["poured_mL"][1](summary)
    spill = OUTCOMES["spilled_mL"][1](summary)
    target = OUTCOMES["target_mL"][1](summary)
    target_error = OUTCOMES["target_error_mL"][1](summary)
    return {
        "spill": Criterion(100.0 * spill / poured if poured > 0 else None, SPILL_LIMIT_PERCENT),
        "landing": Criterion(OUTCOMES["landing_error_mm"][1](summary), LANDING_LIMIT_MM),
        "partial": Criterion(None if target is None else 100.0 * abs(target_error) / target, PARTIAL_LIMIT_PERCENT,
                             applies=target is not None),
    }


def pour_row(pour: HeldoutPour, summary: dict | None, failed: dict | None) -> dict[str, Any]:
    """One row: the scene, its solver and fill, its outcome (or why it has none) and its criteria."""
    scene = pour.scene
    row: dict[str, Any] = {
        "scene": pour.path.stem,
        "file": pour.path.as_posix(),
        "solver": f"{scene.fluid.pressure_solver.value} {scene.fluid.dim}-D",
        "pourer": f"{scene.vessels.pourer.shape.value} {1e3 * scene.vessels.pourer.inner_width:.0f} mm",
        "fill_percent": 100.0 * scene.liquid.fill_depth / scene.vessels.pourer.inner_height,
        "pour_fraction": scene.liquid.pour_fraction,
        "catcher_home_x_m": scene.placement.catcher_home_x,
        "failure": None if failed is None else f"{failed['kind']}: {failed['error']}",
    }
    if summary is None:
        row.update(poured_mL=None, spilled_mL=None, pour_done=None, landing_samples=None, target_mL=None, wall_time_s=None)
        checks = {"spill": Criterion(None, SPILL_LIMIT_PERCENT), "landing": Criterion(None, LANDING_LIMIT_MM),
                  "partial": Criterion(None, PARTIAL_LIMIT_PERCENT, applies=scene.liquid.pour_fraction < 1.0)}
    else:
        row.update(poured_mL=OUTCOMES["poured_mL"][1](summary), spilled_mL=OUTCOMES["spilled_mL"][1](summary),
                   pour_done=summary["pour_done"], landing_samples=summary["landing"].get("samples", 0),
                   target_mL=OUTCOMES["target_mL"][1](summary), wall_time_s=OUTCOMES["wall_time_s"][1](summary))
        checks = criteria(summary)
    row["criteria"] = checks
    row["passed"] = summary is not None and all(c.passed for c in checks.values())
    return row


def collect_rows(pours: list[HeldoutPour], store: SweepStore) -> list[dict[str, Any]]:
    """Every pour's row, from its run folder or its recorded failure ('not run' where it has neither)."""
    import json

    rows = []
    for pour in pours:
        if store.is_complete(pour.key):
            summary = json.loads((store.run_folder(pour.key) / "summary.json").read_text())
            rows.append(pour_row(pour, summary, None))
        else:
            rows.append(pour_row(pour, None, store.failure(pour.key) or {"kind": "not run", "error": "no run folder"}))
    return rows


def _number(value: float | None, digits: int = 1) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def _verdict(c: Criterion) -> str:
    if not c.applies:
        return "n/a"
    return "PASS" if c.passed else "FAIL"


def markdown(rows: list[dict[str, Any]], header: str) -> str:
    """The report: ``header``, the thresholds, one table row per scene, the count of passing rows, and each failed
    pour's line."""
    lines = [
        header, "",
        f"Acceptance: spill <= {SPILL_LIMIT_PERCENT:g} % of the poured volume; landing error (median, CFS) <= "
        f"{LANDING_LIMIT_MM:g} mm; a partial pour within {PARTIAL_LIMIT_PERCENT:g} % of its target. A row passes when "
        f"each of its checks does.", "",
        "| scene | solver | pourer | fill (% of height) | pour fraction | catcher x (m) | poured (mL) | spill (mL) "
        f"| spill (% of poured), limit {SPILL_LIMIT_PERCENT:g} % | verdict | landing median (mm), limit {LANDING_LIMIT_MM:g} mm "
        f"| verdict | partial error (% of target), limit {PARTIAL_LIMIT_PERCENT:g} % | verdict | row |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---|---:|---|---:|---|---|",
    ]
    for r in rows:
        c = r["criteria"]
        lines.append(
            f"| {r['scene']} | {r['solver']} | {r['pourer']} | {r['fill_percent']:.0f} | "
            f"{r['pour_fraction']:g} | {r['catcher_home_x_m']:.2f} | {_number(r['poured_mL'])} | "
            f"{_number(r['spilled_mL'])} | {_number(c['spill'].value, 2)} | {_verdict(c['spill'])} | "
            f"{_number(c['landing'].value)} | {_verdict(c['landing'])} | "
            f"{_number(c['partial'].value, 2) if c['partial'].applies else 'n/a'} | "
            f"{_verdict(c['partial']) if c['partial'].applies else ''} | {'PASS' if r['passed'] else 'FAIL'} |")
    passed = sum(r["passed"] for r in rows)
    walls = [r["wall_time_s"] for r in rows if r["wall_time_s"] is not None]
    lines += ["", f"{passed} of {len(rows)} rows pass. Simulation wall time of the {len(walls)} pours (summary.json "
              f"`wall_time`, on one thread; it depends on the machine's load): {sum(walls) / 60:.0f} min in all, "
              f"{min(walls, default=0):.0f} to {max(walls, default=0):.0f} s each."]
    notes = [f"- {r['scene']}: {r['failure']}" for r in rows if r["failure"]]
    notes += [f"- {r['scene']}: the pour did not end as done (it ran to coupling.max_duration)"
              for r in rows if r["pour_done"] is False]
    if notes:
        lines += ["", *notes]
    return "\n".join(lines) + "\n"


def rows_csv(rows: list[dict[str, Any]]) -> str:
    """The rows as CSV: the scene's columns, then each criterion's value, limit and verdict, then the row's."""
    import csv
    import io

    text = io.StringIO()
    writer = None
    for r in rows:
        flat = {k: v for k, v in r.items() if k not in ("criteria", "passed")}
        for name, c in r["criteria"].items():
            flat.update({f"{name}_value": c.value, f"{name}_limit": c.limit, f"{name}_verdict": _verdict(c)})
        flat["row"] = "PASS" if r["passed"] else "FAIL"
        if writer is None:
            writer = csv.DictWriter(text, fieldnames=list(flat), lineterminator="\n")
            writer.writeheader()
        writer.writerow({k: "" if v is None else v for k, v in flat.items()})
    return text.getvalue()
