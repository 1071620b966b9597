"""The slosh-study table from a sweep's output: a synthetic pour whose numbers are known."""

import csv
import json
from pathlib import Path

import numpy as np

from cosim.bench.slosh_study import COLUMNS, study_table


def _write_pour(folder: Path) -> None:
    folder.mkdir(parents=True)
    t = np.round(np.arange(0.0, 3.0, 0.01), 2)
    phase = np.where(t < 1.0, "sim_hold", np.where(t < 2.0, "sim_damp", "cfs"))
    sigma = np.where(phase == "sim_damp", 0.04 * np.exp(-3.0 * (t - 1.0)), 0.0)
    # CFS pours 90 % of the 2 L by 2.4 s at 15 +- 2 mm, then the rest drains at 0.3 mm (left out of h_q's spread)
    poured = 2e-3 * np.clip(0.9 * (t - 2.0) / 0.395, 0.0, 1.0)  # 90 % between the samples at 2.39 and 2.40 s
    h_q = np.where(phase == "cfs", np.where(t < 2.4, 0.015 + 0.002 * (-1.0) ** np.arange(t.size), 0.0003), -0.005)
    with open(folder / "series.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["t", "phase", "tilt", "theta1", "h_q", "poured_volume"])
        writer.writerows(zip(t, phase, np.zeros_like(t), sigma, h_q, poured))
    summary = {
        "poured_volume": 2e-3, "spilled_volume": 2e-5, "outflow": {"steady_outflow": 1.8},
        "scene": {"coupling": {"start_delay": 0.2}},
        "transitions": [{"from": "sim_damp", "to": "cfs", "reason": "t2 done: slosh damped, |sigma| <= 0.01 rad"}],
        "phases": [{"phase": "done", "start": 2.9, "end": 3.0}],
    }
    (folder / "summary.json").write_text(json.dumps(summary))


def test_table_from_a_known_pour(tmp_path: Path) -> None:
    _write_pour(tmp_path / "pours" / "a")
    with open(tmp_path / "sweep.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["liquid.fill_depth", "status", "failure", "error", "poured_mL", "run_folder"])
        writer.writerow([0.15, "done", "", "", 2000, "pours/a"])
        writer.writerow([0.18, "failed", "bad input", "liquid.fill_depth: too high", "", ""])
    lines = study_table([tmp_path]).splitlines()
    assert lines[0] == "| liquid.fill_depth | " + " | ".join(COLUMNS) + " |"
    cells = [c.strip() for c in lines[2].strip("|").split("|")]
    # spill 1 %, steady at 1.8 s, h_q 15 +- 2 mm from 2.0 to 2.4 s (median 15, quartiles 13 and 17), t1 and t2 1.0 s each,
    # sigma 0.040 -> 0.04 e^-2.25 = 0.004 rad (the last half period starts at 1.75 s)
    assert cells == ["0.15", "1.00", "1.80", "15.0, 4.0", "1.00", "1.00", "t2 done", "0.040", "0.004", "2.90"]
    assert "failed: liquid.fill_depth: too high" in lines[3]
