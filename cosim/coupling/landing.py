"""Where the SPH stream actually lands, against where the catcher controller predicted it would.

The controller predicts, each control step, the world x at which liquid leaving the pour lip *now* crosses the
height of vessel B's rim (Camporredondo et al. 2019, Eqs. 6-7, with the SPH v_q). The liquid it speaks about arrives there one fall time
later. So the prediction made at the launch time t_l = t - t_fall is compared with the stream measured crossing the
rim plane at t: the median x of the falling particles in a thin band around the rim height
(:meth:`cosim.coupling.measure.LiquidProbe.stream_crossing_x`, on the fluid's device).
"""

from __future__ import annotations

import numpy as np

# Half-height (in particle spacings) of the band around the rim plane in which falling particles are sampled: one
# spacing each way holds the stream's particles of about one control period at the 10 ms rate and 3 m/s.
BAND_SPACINGS = 1.0
# A particle counts as part of the falling stream when it moves down faster than this fraction of the free-fall
# speed from the lip to the rim (splashes and the liquid already in vessel B move slower).
MIN_FALL_SPEED_FRACTION = 0.5


def landing_accuracy(
    t: np.ndarray, predicted: np.ndarray, fall_time: np.ndarray, measured: np.ndarray, in_cfs: np.ndarray
) -> dict:
    """Errors (m) of the landing prediction over the control steps whose launch time lay in CFS.

    ``t`` (n,) s control times; ``predicted`` (n,) m the controller's landing x; ``fall_time`` (n,) s the fall time
    of that prediction (NaN when nothing flowed, the catcher then aimed from a weir estimate); ``measured`` (n,) m
    the stream's crossing x (NaN when none); ``in_cfs`` (n,) bool. A sample at t pairs the measurement at t with
    the prediction at the launch time t_l solving t_l + t_fall(t_l) = t (interpolated between control steps).
    """
    t = np.asarray(t, float)
    arrival = t + np.asarray(fall_time, float)
    flowing = np.isfinite(arrival) & np.asarray(in_cfs, bool)
    errors: list[float] = []
    times: list[float] = []
    if flowing.sum() >= 2:
        period = float(np.median(np.diff(t)))
        ta, tl, xp = arrival[flowing], t[flowing], np.asarray(predicted, float)[flowing]
        order = np.argsort(ta, kind="stable")  # arrival grows with launch time for a smooth jet
        ta, xp_sorted, tl_sorted = ta[order], xp[order], tl[order]
        for k in np.flatnonzero(np.isfinite(measured)):
            if not ta[0] <= t[k] <= ta[-1]:
                continue
            launch = np.interp(t[k], ta, tl_sorted)
            # only where the launch fell in a flowing CFS stretch, not in a gap between two
            if np.min(np.abs(tl - launch)) <= 1.5 * period:
                errors.append(float(measured[k] - np.interp(t[k], ta, xp_sorted)))
                times.append(float(t[k]))
    e = np.abs(np.asarray(errors))
    if len(e) == 0:
        return {"samples": 0}
    return {
        "samples": int(len(e)),
        "median_abs_error": float(np.median(e)),
        "p90_abs_error": float(np.quantile(e, 0.9)),
        "max_abs_error": float(e.max()),
        "mean_error": float(np.mean(errors)),
        "first_time": float(times[0]),
        "last_time": float(times[-1]),
    }
