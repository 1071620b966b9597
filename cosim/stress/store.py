"""Resumable result file: one CSV row per configuration, keyed by the configuration's id, rewritten atomically
after every configuration (a reader or an interrupted run never sees a half-written file)."""

from __future__ import annotations

import csv
import dataclasses
import math
from pathlib import Path

from cosim.atomic_files import atomic_path
from cosim.errors import InputError
from cosim.stress.classify import Outcome
from cosim.stress.matrix import StressConfig
from cosim.stress.runner import Measurement

CONFIG_COLUMNS = ["id", "motion", "level", "fill", "across", "cfl_factor", "dim", "solver", "layers", "can_spill"]
MEASUREMENT_COLUMNS = [f.name for f in dataclasses.fields(Measurement) if f.name != "failure"]
COLUMNS = CONFIG_COLUMNS + ["outcome"] + MEASUREMENT_COLUMNS + ["message"]
FLOAT_COLUMNS = {f.name for f in dataclasses.fields(Measurement) if f.type in ("float", float)} | {"level", "fill", "cfl_factor"}
INT_COLUMNS = {f.name for f in dataclasses.fields(Measurement) if f.type in ("int", int)} | {"across", "dim", "layers"}


def make_row(config: StressConfig, outcome: Outcome, message: str, m: Measurement | None) -> dict:
    """The CSV row of one configuration (measurement columns empty when the run raised an unexpected error)."""
    row = {
        "id": config.id, "motion": config.motion.value, "level": config.level, "fill": config.fill,
        "across": config.across, "cfl_factor": config.cfl_factor, "dim": config.dim, "solver": config.solver,
        "layers": config.layers, "can_spill": int(config.can_spill), "outcome": outcome.value, "message": message,
    }
    for name in MEASUREMENT_COLUMNS:
        row[name] = getattr(m, name) if m is not None else ""
    return row


def _parse(row: dict) -> dict:
    out = dict(row)
    for k, v in row.items():
        if v == "":
            out[k] = math.nan if k in FLOAT_COLUMNS else None
        elif k in FLOAT_COLUMNS:
            out[k] = float(v)
        elif k in INT_COLUMNS or k == "can_spill":
            out[k] = int(v)
    return out


class ResultStore:
    """Rows by configuration id, in the order they were completed; ``path`` is read on creation (unless
    ``fresh``) and rewritten on every :meth:`add`."""

    def __init__(self, path: Path, fresh: bool = False):
        self.path = Path(path)
        self.rows: dict[str, dict] = {}
        if not fresh and self.path.exists():
            with self.path.open(newline="") as f:
                reader = csv.DictReader(f)
                if reader.fieldnames != COLUMNS:
                    raise InputError(f"{self.path}: not a stress result file of this version (columns differ); "
                                     "rerun with --fresh or choose another --out")
                self.rows = {r["id"]: _parse(r) for r in reader}

    def __contains__(self, config_id: str) -> bool:
        return config_id in self.rows

    def add(self, row: dict) -> None:
        """Record ``row`` (from :func:`make_row`), held as it reads back from the file, and rewrite the file."""
        self.rows[row["id"]] = _parse({k: str(v) for k, v in row.items()})
        with atomic_path(self.path) as tmp, tmp.open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=COLUMNS)
            writer.writeheader()
            writer.writerows(self.rows.values())
