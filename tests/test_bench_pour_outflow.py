"""The pour's discharge-coefficient fit recovers the coefficient of a synthetic weir outflow."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from cosim.bench import pour_outflow

DT = 0.01  # s, the control step
DEPTH = 0.1  # m, crest length of the synthetic 2-D pourer
SPACING = 0.005  # m
PARTICLES = 1000


def synthetic_run(folder, coefficient: float) -> None:
    """A run folder whose CFS outflow follows the weir law at ``coefficient`` with a head that varies, and stretches
    the fit must skip: other phases (outflow not following the law) and unmeasured heads (the probe's -inner height)."""
    t = np.arange(0.0, 12.0, DT)
    phase = np.where(t < 2.0, "sim_damp", np.where(t < 11.0, "cfs", "return"))
    h_q = 0.012 + 0.006 * np.sin(2.0 * math.pi * t / 3.0)
    h_q[(t > 6.0) & (t < 6.5)] = -0.191
    rate = pour_outflow.weir_factor(DEPTH) * coefficient * np.clip(h_q, 0.0, None) ** 1.5
    rate[phase != "cfs"] = 3e-5  # another phase's outflow, which the law does not describe
    rate[h_q < 0.0] = 2e-5  # the liquid keeps pouring while its surface is unmeasurable
    initial = PARTICLES * SPACING**2 * DEPTH
    volume = initial - np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * DT)])
    with open(folder / "series.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "phase", "h_q", "volume_in_pourer"])
        w.writerows(zip(t, phase, h_q, volume))
    summary = {"dim": 2, "initial_volume": initial, "particles": PARTICLES, "particle_spacing": SPACING,
               "scene": {"controller": {"catcher": {"discharge_coefficient": 0.6}}}}
    (folder / "summary.json").write_text(json.dumps(summary))


def test_the_fit_recovers_the_weir_coefficient_of_a_synthetic_pour(tmp_path) -> None:
    synthetic_run(tmp_path, 0.72)
    fit = pour_outflow.fit_run(tmp_path)
    assert fit.crest_length == pytest.approx(DEPTH, rel=1e-12)
    assert fit.coefficient == pytest.approx(0.72, rel=1e-3)  # trapezoid rule on both sides: discretisation only
    assert fit.q1 <= fit.median <= fit.q3
    assert fit.median == pytest.approx(0.72, rel=1e-3)
    assert fit.windows == 16  # 9 s of CFS in 0.5 s windows, less the two the unmeasured stretch breaks
    assert 0.006 < fit.mean_head < 0.018


def test_the_command_reports_against_the_catchers_coefficient(tmp_path, capsys) -> None:
    synthetic_run(tmp_path, 0.9)
    assert pour_outflow.main([str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["coefficient"] == pytest.approx(0.9, rel=1e-3) and out["assumed"] == 0.6


def test_bad_input_is_one_line_and_status_2(tmp_path, capsys) -> None:
    assert pour_outflow.main([str(tmp_path / "missing")]) == 2
    assert capsys.readouterr().err.startswith("error: RUN: ")
    synthetic_run(tmp_path, 0.6)
    assert pour_outflow.main([str(tmp_path), "--window", "-1"]) == 2
    assert "--window" in capsys.readouterr().err
