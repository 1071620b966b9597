"""A linear filter run one sample at a time: y = (b(z) / a(z)) x, for a measurement filtered inside a control loop.

The coefficients come from a discrete transfer function (e.g. python-control's ``c2d`` of a continuous design),
so that the filter the loop runs is exactly the one its design includes. Stepping uses scipy's ``lfilter`` with
its state carried between samples (direct form II transposed).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from controllers.errors import ControllerInputError


class SampledFilter:
    """y_k from x_k through b(z) / a(z) (coefficients highest power first, a[0] != 0), unit DC gain required so that a
    filter started at rest on a value holds it. Units of x and y are the caller's."""

    def __init__(self, numerator: Sequence[float], denominator: Sequence[float]) -> None:
        import scipy.signal  # seconds to load: only where a filter is built, so that reading a configuration stays fast

        b, a = np.asarray(numerator, dtype=float), np.asarray(denominator, dtype=float)
        if a.size == 0 or a[0] == 0.0 or b.size > a.size:
            raise ControllerInputError("sampled filter: needs a proper b(z) / a(z) with a nonzero leading denominator")
        if not np.isclose(np.sum(b), np.sum(a), rtol=1e-9, atol=0.0):
            raise ControllerInputError(f"sampled filter: DC gain must be 1, got {np.sum(b) / np.sum(a):.6g}")
        self._b = np.concatenate([np.zeros(a.size - b.size), b]) / a[0]
        self._a = a / a[0]
        self._rest = scipy.signal.lfilter_zi(self._b, self._a) if self._a.size > 1 else np.zeros(0)  # a gain has no state
        self._state = np.zeros(self._a.size - 1)
        self._lfilter = scipy.signal.lfilter

    def reset(self, value: float) -> None:
        """At rest on ``value``: every later sample of ``value`` outputs ``value``."""
        self._state = self._rest * float(value)

    def step(self, x: float) -> float:
        """One sample of input ``x``; returns the filtered output."""
        y, self._state = self._lfilter(self._b, self._a, [float(x)], zi=self._state)
        return float(y[0])
