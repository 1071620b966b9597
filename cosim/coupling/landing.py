"""Where the SPH stream actually lands, against where the catcher controller predicted it would.

The controller predicts, each control step, the world x at which liquid leaving the pour lip *now* crosses the
height of vessel B's rim (Camporredondo et al. 2019, Eqs. 6-7, with the SPH v_q). The liquid it speaks about arrives there one fall time
later. So the prediction made at the launch time t_l = t - t_fall is compared with the stream measured crossing the
rim plane at t: the median x of the falling particles in a thin band around the rim height
(:meth:`cosim.coupling.measure.LiquidProbe.stream_crossing_x`, on the fluid's device).

At the default resolution the band holds one particle at most instants, and the particles of one stream cross the
rim plane scattered by about a particle spacing about the stream's centre (each leaves the lip with its own
velocity; docs/landing.md). A single sample's error is therefore mostly that scatter, which no prediction of the
stream can remove. The errors are also split over a window of :data:`cosim.coupling.outflow.RATE_WINDOW` s (the
span over which the pour's outflow counts as steady): the mean error of the samples within half that window each
way is the prediction's error on the stream's centre, and each sample's error less that mean is its scatter.
"""

from __future__ import annotations

import numpy as np

from cosim.coupling.outflow import RATE_WINDOW

# Half-height (in particle spacings) of the band around the rim plane in which falling particles are sampled: one
# spacing each way holds the stream's particles of about one control period at the 10 ms rate and 3 m/s.
BAND_SPACINGS = 1.0
# A particle counts as part of the falling stream when it moves down faster than this fraction of the free-fall
# speed from the lip to the rim (splashes and the liquid already in vessel B move slower).
MIN_FALL_SPEED_FRACTION = 0.5


def landing_pairs(
    t: np.ndarray, predicted: np.ndarray, fall_time: np.ndarray, measured: np.ndarray, in_cfs: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The control steps k whose measurement counts and the launch time t_l (s) each is paired with.

    ``t`` (n,) s control times; ``predicted`` (n,) m the controller's landing x; ``fall_time`` (n,) s the fall time
    of that prediction (NaN when nothing flowed, the catcher then aimed from a weir estimate); ``measured`` (n,) m
    the stream's crossing x (NaN when none); ``in_cfs`` (n,) bool. A sample at t pairs the measurement at t with
    the prediction at the launch time t_l solving t_l + t_fall(t_l) = t (interpolated between control steps), kept
    where that launch fell in a flowing CFS stretch. Returns (indices k, t_l).
    """
    t = np.asarray(t, float)
    arrival = t + np.asarray(fall_time, float)
    flowing = np.isfinite(arrival) & np.asarray(in_cfs, bool)
    steps: list[int] = []
    launches: list[float] = []
    if flowing.sum() >= 2:
        period = float(np.median(np.diff(t)))
        ta, tl = arrival[flowing], t[flowing]
        order = np.argsort(ta, kind="stable")  # arrival grows with launch time for a smooth jet
        ta, tl_sorted = ta[order], tl[order]
        for k in np.flatnonzero(np.isfinite(measured)):
            if not ta[0] <= t[k] <= ta[-1]:
                continue
            launch = np.interp(t[k], ta, tl_sorted)
            # only where the launch fell in a flowing CFS stretch, not in a gap between two
            if np.min(np.abs(tl - launch)) <= 1.5 * period:
                steps.append(int(k))
                launches.append(float(launch))
    return np.array(steps, dtype=int), np.array(launches)


def paired_prediction(t: np.ndarray, predicted: np.ndarray, fall_time: np.ndarray, in_cfs: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The prediction (m) paired with measurements at the times ``at`` (s): the controller's landing x at the launch
    times, interpolated along the arrival times t + t_fall of the flowing CFS steps (:func:`landing_pairs`)."""
    t = np.asarray(t, float)
    arrival = t + np.asarray(fall_time, float)
    flowing = np.isfinite(arrival) & np.asarray(in_cfs, bool)
    ta, xp = arrival[flowing], np.asarray(predicted, float)[flowing]
    order = np.argsort(ta, kind="stable")
    return np.interp(np.asarray(at, float), ta[order], xp[order])


def landing_accuracy(
    t: np.ndarray, predicted: np.ndarray, fall_time: np.ndarray, measured: np.ndarray, in_cfs: np.ndarray
) -> dict:
    """Errors (m) of the landing prediction over the control steps whose launch time lay in CFS (arguments as
    :func:`landing_pairs`): the measurement at t against the prediction paired with it (``median_abs_error``,
    ``p90_abs_error``, ``max_abs_error``, ``mean_error``), and split over the window RATE_WINDOW (module
    docstring): ``centre_median_abs_error`` and ``centre_p90_abs_error``, of the mean error within +-RATE_WINDOW / 2
    of each sample; ``scatter_median_abs``, of each error less that mean."""
    t = np.asarray(t, float)
    steps, _ = landing_pairs(t, predicted, fall_time, measured, in_cfs)
    if len(steps) == 0:
        return {"samples": 0}
    errors = np.asarray(measured, float)[steps] - paired_prediction(t, predicted, fall_time, in_cfs, t[steps])
    e = np.abs(errors)
    times = t[steps]
    centre = np.array([errors[np.abs(times - tk) <= 0.5 * RATE_WINDOW].mean() for tk in times])
    return {
        "samples": int(len(e)),
        "median_abs_error": float(np.median(e)),
        "p90_abs_error": float(np.quantile(e, 0.9)),
        "max_abs_error": float(e.max()),
        "mean_error": float(np.mean(errors)),
        "centre_median_abs_error": float(np.median(np.abs(centre))),
        "centre_p90_abs_error": float(np.quantile(np.abs(centre), 0.9)),
        "scatter_median_abs": float(np.median(np.abs(errors - centre))),
        "first_time": float(t[steps[0]]),
        "last_time": float(t[steps[-1]]),
    }
