"""Dam break against Martin & Moyce: every reference point with its Z error and time lead, no time shift."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.validation import dam_break


def test_first_reach_interpolates_the_first_crossing() -> None:
    T = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    Z = np.array([1.0, 1.5, 1.4, 2.5, 3.0])  # dips back once: the first crossing counts
    assert dam_break.first_reach(T, Z, 1.25) == pytest.approx(0.5)
    assert dam_break.first_reach(T, Z, 2.0) == pytest.approx(2.0 + 0.6 / 1.1)
    assert dam_break.first_reach(T, Z, 1.0) == 0.0
    assert math.isnan(dam_break.first_reach(T, Z, 3.5))


def test_every_reference_point_is_reported_without_a_time_shift() -> None:
    p = dam_break.Params(width=0.05, spacing=0.005, t_max=2.2, solver="wcsph")  # coarse: 10 across
    result = dam_break.run(p)
    ref_T, ref_Z = dam_break.martin_moyce()
    points = result.raw["reference_points"]
    assert [pt["T"] for pt in points] == pytest.approx(list(ref_T[ref_T <= result.raw["T"][-1]]))
    assert len(points) == len(result.metrics) == 3
    T, Z = np.array(result.raw["T"]), np.array(result.raw["Z"])
    for pt, zr in zip(points, ref_Z):
        assert pt["Z_reference"] == pytest.approx(zr)
        assert pt["Z"] == pytest.approx(np.interp(pt["T"], T, Z))  # read at the experiment's own T
        assert pt["error"] == pytest.approx((pt["Z"] - zr) / zr)
        if math.isfinite(pt["time_lead"]):  # a front ahead of the experiment reached its Z earlier
            assert (pt["time_lead"] > 0) == (pt["error"] > 0)
