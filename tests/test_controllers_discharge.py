"""The discharge coefficient CFS's feed-forward is scaled by: the weir law, and the estimate from outflow and head."""

import math

import numpy as np
import pytest

from controllers.discharge import DischargeEstimate, weir_flow

G = 9.81
L = 0.1  # m, crest length
DT = 0.01  # s


def test_weir_flow_is_the_sharp_crested_weir_law() -> None:
    h, c = 0.012, 0.7
    assert weir_flow(h, c, L, G) == pytest.approx(2.0 / 3.0 * c * math.sqrt(2.0 * G) * L * h**1.5, rel=1e-12)
    assert weir_flow(-0.003, c, L, G) == 0.0  # a negative head pours nothing


def test_estimate_starts_at_the_prior_and_keeps_it_while_nothing_flows() -> None:
    est = DischargeEstimate(0.6, L, 0.005, 1.0, G)
    assert est.coefficient == pytest.approx(0.6, rel=1e-12)
    for _ in range(500):  # 5 s below the crest
        est.update(0.0, -0.004, DT)
    assert est.coefficient == pytest.approx(0.6, rel=1e-9)
    assert est.flow(0.005) == pytest.approx(weir_flow(0.005, 0.6, L, G), rel=1e-9)


def test_estimate_finds_the_coefficient_of_a_varying_head_and_ignores_the_head_itself() -> None:
    """The liquid pours with C_d = 0.95 at a head that sloshes by +-40 %: after ten time constants the estimate is
    the liquid's C_d (the prior's share has decayed to e^-10), not moved by the head's swing."""
    est = DischargeEstimate(0.6, L, 0.005, 1.0, G)
    t = np.arange(0.0, 10.0, DT)
    head = 0.008 * (1.0 + 0.4 * np.sin(2.0 * math.pi * 2.0 * t))
    for h in head:
        est.update(weir_flow(float(h), 0.95, L, G), float(h), DT)
    assert est.coefficient == pytest.approx(0.95, rel=1e-3)
