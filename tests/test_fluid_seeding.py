"""The seeding refuses a liquid its particles cannot resolve, with the remedy in one line."""

import pytest

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig
from cosim.fluid.seeding import MIN_FILL_LAYERS, fill_layers, fill_vessel
from cosim.vessel import VesselSpec

SEED = VesselSpec()  # the pouring vessel of Camporredondo et al. (2019): 0.191 x 0.1 x 0.191 m


def test_too_few_layers_is_refused_with_the_spacing_that_would_do() -> None:
    cfg = FluidConfig(dim=2, spacing=0.191 / 12)
    thin = 0.0191  # 10 % fill: one layer at 12 across
    assert fill_layers(SEED, thin, cfg.spacing) < MIN_FILL_LAYERS
    with pytest.raises(InputError, match=r"^fill_depth: .* particle layers .* at least 3 are needed .*spacing <="):
        fill_vessel(SEED, thin, cfg)
    finer = FluidConfig(dim=2, spacing=thin / MIN_FILL_LAYERS)
    assert len(fill_vessel(SEED, thin, finer).positions) > 0


def test_too_few_particles_across_the_depth_in_3d_is_refused() -> None:
    cfg = FluidConfig(dim=3, spacing=0.191 / 6)  # 3 across the 0.1 m depth
    with pytest.raises(InputError, match=r"^spacing: .* 3 particles across the vessel's depth"):
        fill_vessel(SEED, 0.15, cfg)
    assert len(fill_vessel(SEED, 0.15, FluidConfig(dim=2, spacing=0.191 / 6)).positions) > 0  # 2-D: no depth
