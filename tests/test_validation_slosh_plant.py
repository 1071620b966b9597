"""Slosh-plant identification: the fit on known ring-downs, and the SPH liquid's plant against potential flow and
against the paper's printed pendulum (coarse 2-D, the paper's vessel)."""

import json
import math

import numpy as np
import pytest

from controllers.slosh import printed_paper_model
from cosim.cli.main import main
from cosim.errors import InputError
from cosim.validation import plant_fit, slosh_plant

B, A = 0.191, 0.1591  # m, the paper's vessel and fill


def _ring_downs(pivots, hinge, omega, zeta, noise, seed=0):
    """sigma(t) after a tilt about each pivot: (H - p) times one damped ring-down, an offset and white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(1, 751) * 0.002
    wd = omega * math.sqrt(1 - zeta**2)
    shape = np.exp(-zeta * omega * t) * np.cos(wd * t + 2.2)
    return t, [1.2 * (hinge - p) * shape - 0.002 + noise * rng.standard_normal(len(t)) for p in pivots]


def test_fit_recovers_a_known_plant():
    hinge, omega, zeta = 0.1155, 12.6, 0.03
    pivots = [0.0, 0.06, 0.1155, 0.14]
    t, sigmas = _ring_downs(pivots, hinge, omega, zeta, noise=0.003)
    fit = plant_fit.identify_plant(pivots, t, sigmas)
    assert fit.omega1 == pytest.approx(omega, rel=0.003)
    assert fit.damping_ratio == pytest.approx(zeta, abs=0.003)
    assert fit.hinge_height == pytest.approx(hinge, abs=0.001)
    assert fit.signed_amplitudes[0] > fit.signed_amplitudes[1] > 0 > fit.signed_amplitudes[3]  # a line through the hinge
    model = fit.slosh_model(9.81)
    assert model.omega1 == pytest.approx(fit.omega1) and model.hinge_height == fit.hinge_height
    assert model.damping_ratio == fit.damping_ratio and model.source == "SPH identification"


def test_a_hinge_below_the_pivots_is_found_by_the_line():
    pivots = [0.08, 0.1, 0.12]
    t, sigmas = _ring_downs(pivots, 0.064, 12.6, 0.02, noise=0.001)  # all pivots above the hinge: one sign
    assert plant_fit.identify_plant(pivots, t, sigmas).hinge_height == pytest.approx(0.064, abs=0.001)


def test_records_without_a_ring_down_give_no_plant():
    t = np.arange(1, 301) * 0.002
    fit = plant_fit.identify_plant([0.0, 0.05, 0.1], t, [np.zeros_like(t)] * 3)
    assert math.isnan(fit.omega1) and math.isnan(fit.hinge_height)
    assert slosh_plant.identified_model(fit, 9.81) is None


def test_fewer_than_three_pivots_are_refused():
    t, sigmas = _ring_downs([0.0, 0.1], 0.1155, 12.6, 0.03, noise=0.0)
    with pytest.raises(InputError, match="pivots"):
        plant_fit.identify_plant([0.0, 0.1], t, sigmas)


@pytest.mark.slow
def test_sph_plant_of_the_papers_vessel_is_potential_flow_not_the_printed_pendulum(capsys):
    """Coarse (16 across B, 2-D, DFSPH): the hinge the liquid shows is the potential-flow one, some 50 mm above
    the hinge of the paper's printed Eqs. 10-11."""
    assert main(["validate", "slosh-plant", "--width", str(B), "--fill", str(A), "--spacing", str(B / 16), "--json", "--no-plot"]) == 0
    case = json.loads(capsys.readouterr().out)["cases"][0]
    assert case["passed"] and case["failures"] == [""] * 4
    assert abs(case["hinge_height_sph"] - case["hinge_height_model"]) <= slosh_plant.HINGE_TOLERANCE
    assert abs(case["omega1_sph"] - case["omega1_model"]) <= slosh_plant.OMEGA_TOLERANCE * case["omega1_model"]
    printed = printed_paper_model(B, case["liquid_depth"]).hinge_height
    assert printed == pytest.approx(0.064, abs=0.003)
    assert case["hinge_height_sph"] - printed > 6 * slosh_plant.HINGE_TOLERANCE
    assert 0.0 < case["damping_ratio_sph"] < 0.1
    identified = case["identified_model"]
    assert identified["l1"] == pytest.approx(9.81 / case["omega1_sph"] ** 2)
    assert len(case["sigma"]) == len(case["pivots"]) == len(case["signed_amplitudes"]) == 4
    assert all(len(s) == len(case["t"]) for s in case["sigma"])
