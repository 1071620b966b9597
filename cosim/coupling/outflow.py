"""When the outflow starts and when it becomes steady: the measure of the SIM-against-open-loop comparison.

The point of SIM (Camporredondo et al. 2019, Sec. 3.1) is to reach a steady outflow sooner. Steady here: the outflow rate, averaged over
a trailing window of RATE_WINDOW s, stays within +-STEADY_TOLERANCE of its own mean for STEADY_HOLD s, that mean
being at least MIN_RATE_FRACTION of the run's peak rate (a trickle is not the pour). The window smooths the
particle-count steps of the SPH volume (one particle of the default 2-D scene is 3.6 mL). The steady outflow is
dated from the start of the first such window.
"""

from __future__ import annotations

import math

import numpy as np

RATE_WINDOW = 0.5  # s
STEADY_TOLERANCE = 0.15  # relative to the mean rate over the hold
MIN_RATE_FRACTION = 0.25  # of the peak windowed rate
STEADY_HOLD = 1.0  # s
FIRST_OUTFLOW_VOLUME = 1e-6  # m^3 (1 mL, below one particle): poured volume that counts as the outflow's start


def outflow_timing(t: np.ndarray, poured: np.ndarray, in_cfs: np.ndarray, start: float) -> dict:
    """First-outflow and steady-outflow times (s after ``start``, the pour's start) from the control-step series
    ``t`` (s), ``poured`` (m^3) and ``in_cfs`` (bool); ``cfs_median_rate`` (m^3/s, the windowed rate's median over
    CFS, for reference). NaN where not reached."""
    t, poured, in_cfs = np.asarray(t, float), np.asarray(poured, float), np.asarray(in_cfs, bool)
    out = {"first_outflow": math.nan, "steady_outflow": math.nan, "cfs_median_rate": math.nan}
    started = np.flatnonzero(poured > FIRST_OUTFLOW_VOLUME)
    if len(started) == 0 or len(t) < 2:
        return out
    out["first_outflow"] = float(t[started[0]] - start)
    dt = float(np.median(np.diff(t)))
    w = max(1, round(RATE_WINDOW / dt))
    rate = np.full_like(t, np.nan)
    rate[w:] = (poured[w:] - poured[:-w]) / (t[w:] - t[:-w])  # trailing-window mean rate at each step
    cfs_rates = rate[in_cfs & np.isfinite(rate)]
    if len(cfs_rates) == 0:
        return out
    out["cfs_median_rate"] = float(np.median(cfs_rates))
    peak = float(np.nanmax(rate))
    hold = max(1, round(STEADY_HOLD / dt))
    for k in range(max(started[0], w), len(t) - hold + 1):
        r = rate[k : k + hold]
        mean = float(r.mean())
        if mean >= MIN_RATE_FRACTION * peak and np.all(np.abs(r - mean) <= STEADY_TOLERANCE * mean):
            out["steady_outflow"] = float(t[k] - RATE_WINDOW - start)
            break
    return out
