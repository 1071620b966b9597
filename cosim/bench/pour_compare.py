"""Differences between two pour runs (raw results of :func:`cosim.bench.runners.run_config`), over the time both
simulated.

- ``poured_curve_error``: RMS over the control steps of the poured volume's difference, divided by the
  reference's initial volume (dimensionless; 0.01 = the curves differ by 1 % of the liquid on average). A run whose
  pour was done when it stopped (the early stop) holds its last poured volume until the other run ends: nothing
  pours after the pour is done (the early-stop pair of :mod:`cosim.bench.plan` measures that), so two whole pours
  that end at different times are compared over the longer one. A run cut off by its time limit is compared only
  over the time it simulated.
- ``landing_error_m``: m, difference of the median measured landing x (where the stream crosses the catcher's rim
  plane, ``series.csv``'s ``landing_measured_x``); NaN when either run had no stream.
- ``joint_rms_rad``: rad, RMS over time and all joints of both arms of the joint position difference of the
  exported (commanded, jerk-limited) trajectories.
- ``final_caught_error``: difference of the volume in the catcher at the end of each run, divided by the
  reference's initial volume (the runs may differ in length: the early-stop pair).
"""

from __future__ import annotations

import math

import numpy as np

POUR_ERRORS = ("poured_curve_error", "landing_error_m", "joint_rms_rad", "final_caught_error")


def _common_grid(t_run: np.ndarray, t_ref: np.ndarray) -> np.ndarray:
    """The reference's sample times that lie within the run's span."""
    return t_ref[(t_ref >= t_run[0] - 1e-9) & (t_ref <= t_run[-1] + 1e-9)]


def _poured_grid(run: dict, reference: dict) -> np.ndarray:
    """s, the times the poured volumes are compared at: the longer run's samples, up to where the shorter one
    stopped unless its pour was done (then its last volume holds)."""
    runs = sorted((run, reference), key=lambda r: r["series"]["t"][-1])
    short, long = (np.asarray(r["series"]["t"], float) for r in runs)
    end = long[-1] if runs[0]["outcome"]["pour_done"] else short[-1]
    return long[(long >= max(short[0], long[0]) - 1e-9) & (long <= end + 1e-9)]


def _median_landing(series: dict) -> float:
    x = np.array([math.nan if v is None else v for v in series["landing_measured_x"]], dtype=float)
    x = x[np.isfinite(x)]
    return float(np.median(x)) if len(x) else math.nan


def compare_pours(run: dict, reference: dict) -> dict[str, float]:
    """The :data:`POUR_ERRORS` of ``run`` against ``reference`` (both raw results with status 'ok')."""
    a, b = run["series"], reference["series"]
    t_run, t_ref = np.asarray(a["t"], float), np.asarray(b["t"], float)
    grid = _poured_grid(run, reference)
    poured = np.interp(grid, t_run, a["poured_volume"]) - np.interp(grid, t_ref, b["poured_volume"])
    initial = float(reference["outcome"]["initial_volume"])
    if a["joint_names"] != b["joint_names"]:
        raise ValueError("pour comparison: the two runs have different joints")
    tq_run, tq_ref = np.asarray(a["trajectory_time"], float), np.asarray(b["trajectory_time"], float)
    q_run, q_ref = np.asarray(a["joint_positions"], float), np.asarray(b["joint_positions"], float)
    tq = _common_grid(tq_run, tq_ref)
    dq = np.stack([np.interp(tq, tq_run, q_run[:, j]) - np.interp(tq, tq_ref, q_ref[:, j]) for j in range(q_ref.shape[1])])
    return {
        "poured_curve_error": float(np.sqrt(np.mean(poured**2)) / initial),
        "landing_error_m": abs(_median_landing(a) - _median_landing(b)),
        "joint_rms_rad": float(np.sqrt(np.mean(dq**2))),
        "final_caught_error": abs(run["outcome"]["caught_volume"] - reference["outcome"]["caught_volume"]) / initial,
    }
