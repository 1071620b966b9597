"""The divergence solve's constraint (``FluidConfig.divergence_constraint``, ``cosim.fluid.dfsph.divergence_error``):
every compressing density rate, or only the rate that would compress a particle past rest density within the step."""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from cosim.cli.main import main
from cosim.errors import InputError
from cosim.fluid.config import DivergenceConstraint, FluidConfig
from cosim.fluid.dfsph import divergence_error
from cosim.fluid.params import SPHParams, make_params

RHO0 = 1000.0


@wp.kernel
def _errors(prm: SPHParams, past_rest: int, rate: wp.array(dtype=float), rho: wp.array(dtype=float), out: wp.array(dtype=float)):
    i = wp.tid()
    out[i] = divergence_error(prm, past_rest, rate[i], rho[i])


def _divergence_errors(constraint: DivergenceConstraint, rate: np.ndarray, rho: np.ndarray) -> np.ndarray:
    prm = make_params(FluidConfig(rest_density=RHO0, divergence_constraint=constraint), n_vessels=1)
    out = wp.zeros(len(rate), dtype=float, device="cpu")
    args = [wp.array(rate, dtype=float, device="cpu"), wp.array(rho, dtype=float, device="cpu")]
    wp.launch(_errors, dim=len(rate), inputs=[prm, int(constraint is DivergenceConstraint.PAST_REST_DENSITY), *args, out], device="cpu")
    return out.numpy()


# dt Drho/Dt (kg/m^3) and the density the solves hold the particle to: compressing and expanding, at, above and below rho0
RATES = np.array([5.0, -5.0, 5.0, 5.0, 5.0, 30.0, -5.0], dtype=np.float32)
DENSITIES = np.array([1000.0, 1000.0, 1010.0, 990.0, 980.0, 980.0, 980.0], dtype=np.float32)


def test_every_compressing_rate_is_an_error_with_every_compression():
    errors = _divergence_errors(DivergenceConstraint.EVERY_COMPRESSION, RATES, DENSITIES)
    np.testing.assert_array_equal(errors, np.maximum(RATES, 0.0))


def test_a_rarefied_particle_may_compress_by_its_shortfall():
    """Past rest density: at or above rho0 the same error as every compression; 10 kg/m^3 below it a rate of 5 is
    no error (the particle closes half its shortfall), a rate of 30 is an error of 10 (what would carry it past)."""
    assert FluidConfig().divergence_constraint is DivergenceConstraint.PAST_REST_DENSITY
    errors = _divergence_errors(DivergenceConstraint.PAST_REST_DENSITY, RATES, DENSITIES)
    np.testing.assert_array_equal(errors, [5.0, 0.0, 5.0, 0.0, 0.0, 10.0, 0.0])


def test_validate_takes_the_setting_from_its_declaration(capsys):
    assert main(["validate", "hydrostatic", "--divergence-constraint", "both_ways"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--divergence-constraint" in err[0] and "'past_rest_density'" in err[0]


def test_the_setting_is_checked_against_its_declaration():
    with pytest.raises(InputError, match="fluid.divergence_constraint"):
        FluidConfig(divergence_constraint="both_ways")
