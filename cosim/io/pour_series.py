"""``series.csv`` of a run folder: the pour's per-control-step signals as plain columns, for scripts and the bench.

One row per control step (10 ms by default). Columns (SI units, rad): ``t`` s; ``phase``; ``tilt``, ``theta1``
rad (measured pourer tilt and free-surface angle); ``h_q`` m, ``v_q``, ``v_q_z`` m/s (height over the crest and
outflow velocity); ``volume_in_pourer``, ``volume_in_catcher``, ``poured_volume``, ``spilled_volume`` m^3
(spilled: left the simulation domain); ``lip_x``, ``lip_z``, ``catcher_rim_z`` m; ``jet_dx``, ``jet_dz`` m (where v_q is measured, from the lip); ``landing_x`` m (predicted),
``landing_measured_x`` m (stream crossing the rim plane, empty when none), ``landing_fall_time`` s;
``target_theta``, ``target_dx``, ``target_dz``, ``smoothed_theta``, ``catcher_dx``, ``smoothed_catcher_dx``
(controller targets before and after the task-space filter, rad and m).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

COLUMNS = (
    "t", "phase", "tilt", "theta1", "h_q", "v_q", "v_q_z", "volume_in_pourer", "volume_in_catcher", "poured_volume",
    "spilled_volume", "lip_x", "lip_z", "jet_dx", "jet_dz", "catcher_rim_z", "landing_x", "landing_measured_x", "landing_fall_time",
    "target_theta", "target_dx", "target_dz", "smoothed_theta", "catcher_dx", "smoothed_catcher_dx",
)


def _cell(value: object) -> str:
    if isinstance(value, str):
        return value
    x = float(value)  # type: ignore[arg-type]
    return "" if math.isnan(x) else repr(x)


def write_series_csv(rows: dict[str, list], path: Path) -> None:
    """Write the pour log's ``rows`` (column name -> per-step values) as ``path`` (CSV with a header)."""
    n = len(rows.get("t", ()))
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(COLUMNS)
        for k in range(n):
            writer.writerow([_cell(rows[c][k]) for c in COLUMNS])


def read_series_csv(path: Path) -> dict[str, list]:
    """The columns of a ``series.csv`` (floats, NaN for empty cells; ``phase`` as strings)."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        out: dict[str, list] = {c: [] for c in reader.fieldnames or ()}
        for row in reader:
            for c, v in row.items():
                out[c].append(v if c == "phase" else (float(v) if v else math.nan))
    return out
