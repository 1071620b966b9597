"""The seeding refuses a liquid its particles cannot resolve, with the remedy in one line, and fills a cylindrical cup
to its wall."""

import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, WallModel
from cosim.fluid.seeding import MIN_FILL_LAYERS, fill_layers, fill_vessel
from cosim.fluid.wall_sampling import sample_vessel_walls
from cosim.vessel import VesselShape, VesselSpec

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


@pytest.mark.parametrize("across", [16, 24])
def test_cylinder_liquid_fills_the_disc_to_the_wall(across) -> None:
    """The 3-D cup's liquid holds pi R^2 times its layers at dx^3 a particle, and its outer ring lies dx/2 inside
    the wall all round, dx from the covering walls' first dummy layer (at R + dx/2), as a box's lattice does. A
    square lattice cut to the disc held 10-15 % less and left a stair-stepped gap to the wall."""
    radius = 0.0955
    cup = VesselSpec(shape=VesselShape.CYLINDER, inner_width=2 * radius, inner_height=0.26)
    cfg = FluidConfig(dim=3, spacing=2 * radius / across, wall_model=WallModel.KERNEL_LAYERS)
    dx = cfg.spacing
    x = fill_vessel(cup, 0.1591, cfg).positions
    layers = fill_layers(cup, 0.1591, dx)
    assert len(x) * dx**3 == pytest.approx(math.pi * radius**2 * layers * dx, rel=0.005)
    assert sorted(set(np.round(x[:, 2] / dx - 0.5, 9))) == list(range(layers))
    r = np.hypot(x[:, 0], x[:, 1])
    assert r.max() == pytest.approx(radius - 0.5 * dx, abs=1e-12)
    outer = x[r > radius - 0.5 * dx - 1e-9]
    sectors = np.floor((np.arctan2(outer[:, 1], outer[:, 0]) + math.pi) / (2 * math.pi) * 36).astype(int) % 36
    assert len(set(sectors)) == 36  # the outer ring goes all round: no stair steps
    layer = x[np.abs(x[:, 2] - 0.5 * dx) < 1e-9]
    gaps = np.linalg.norm(layer[:, None, :] - layer[None, :, :], axis=2) + np.eye(len(layer))
    assert gaps.min() > 0.8 * dx  # no two particles closer than a lattice would put them (within 20 %)
    walls, _ = sample_vessel_walls(cup, cfg)
    side = walls[walls[:, 2] > 0.0]
    assert np.hypot(side[:, 0], side[:, 1]).min() == pytest.approx(radius + 0.5 * dx, abs=1e-9)
