"""The sample-by-sample filter the PID reads theta1 through is the transfer function its design includes."""

import math

import control as ct
import numpy as np
import pytest

from controllers.errors import ControllerInputError
from controllers.pid import PidDesignSpec, coefficients, measurement_filter
from controllers.sampled_filter import SampledFilter
from controllers.slosh import potential_flow_model

DT = 0.01  # s


def test_stepping_is_the_transfer_function() -> None:
    m = measurement_filter(PidDesignSpec(), potential_flow_model(0.191, 0.1591), DT)
    x = np.random.default_rng(3).normal(0.0, 0.01, 400)
    f = SampledFilter(*coefficients(m))
    f.reset(0.0)
    y = np.array([f.step(v) for v in x])
    _, expected = ct.forced_response(m, T=np.arange(x.size) * DT, U=x)
    assert np.allclose(y, expected, rtol=1e-9, atol=1e-14)


def test_reset_holds_a_value() -> None:
    f = SampledFilter(*coefficients(measurement_filter(PidDesignSpec(), potential_flow_model(0.191, 0.1591), DT)))
    f.reset(0.37)
    assert [f.step(0.37) for _ in range(50)] == pytest.approx([0.37] * 50, abs=1e-14)


def test_a_filter_without_unit_dc_gain_is_refused() -> None:
    with pytest.raises(ControllerInputError, match=r"^sampled filter: DC gain must be 1"):
        SampledFilter([0.5], [1.0, -0.2])
    with pytest.raises(ControllerInputError, match=r"^sampled filter: needs a proper"):
        SampledFilter([1.0, 0.0, 0.0], [1.0, -0.0])
    assert math.isfinite(SampledFilter([1.0], [1.0]).step(2.0))
