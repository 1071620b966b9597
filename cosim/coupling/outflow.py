"""When the outflow starts and when it becomes steady: the measure of issue 4's SIM-against-open-loop comparison.

The point of SIM (seed Sec. 3.1) is to reach a steady outflow sooner. Steady here: the outflow rate, averaged over
a sliding window of RATE_WINDOW s, stays within STEADY_TOLERANCE of the CFS median rate for STEADY_HOLD s. The
window smooths the particle-count steps of the SPH volume (one particle of the default 2-D scene is 3.6 mL).
"""

from __future__ import annotations

import math

import numpy as np

RATE_WINDOW = 0.5  # s
STEADY_TOLERANCE = 0.3  # relative to the CFS median rate
STEADY_HOLD = 1.0  # s
FIRST_OUTFLOW_VOLUME = 1e-6  # m^3 (1 mL, below one particle): poured volume that counts as the outflow's start


def outflow_timing(t: np.ndarray, poured: np.ndarray, in_cfs: np.ndarray, start: float) -> dict:
    """First-outflow and steady-outflow times (s after ``start``, the pour's start) from the control-step series
    ``t`` (s), ``poured`` (m^3) and ``in_cfs`` (bool); ``cfs_median_rate`` (m^3/s). NaN where not reached."""
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
    ref = float(np.median(cfs_rates))
    out["cfs_median_rate"] = ref
    if not ref > 0.0:
        return out
    near = np.abs(rate - ref) <= STEADY_TOLERANCE * ref
    hold = max(1, round(STEADY_HOLD / dt))
    for k in range(started[0], len(t) - hold + 1):
        if near[k : k + hold].all():
            # the window ending at k measured liquid launched over the preceding RATE_WINDOW s
            out["steady_outflow"] = float(t[k] - RATE_WINDOW - start)
            break
    return out
