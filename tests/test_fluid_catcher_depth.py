"""2-D liquid in a vessel of another depth than it was seeded for (``cosim.fluid.model``): a particle keeps its 3-D
volume V = dx^2 depth_2d and takes the depth d of the vessel it enters, so a caught column stands V / (d w) high
and weighs rho0 g V on its vessel."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import pytest

from cosim.fluid.config import GRAVITY, FluidConfig
from cosim.fluid.model import caught_liquid_mass, densest_smoothing_ratio
from cosim.fluid.seeding import fill_vessel, liquid_block
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.vessel import VesselSpec

SEEDED_DEPTH = 0.10  # m, the depth the liquid is seeded for (a pourer's)
TANK_DEPTH = 0.14  # m, the receiving tank's (a catcher's)
TANK_WIDTH = 0.1  # m
COLUMN = 0.05  # m, the caught column's height V / (d w)
HEIGHT_TOLERANCE = 0.02  # the hydrostatic validation's pressure tolerance, applied to the column's height
WEIGHT_TOLERANCE = 0.01  # the hydrostatic validation's vertical-reaction tolerance
SETTLE = 1.2  # s: the dropped block lands by 0.3 s and is at rest (speeds ~0.01 m/s) by 0.6 s
AVERAGE = 0.3  # s, the last stretch over which the vessel's vertical force is averaged (the liquid at rest)
INTERVAL = 0.02  # s


def _config(solver: str, dx: float, top: float, **numerics) -> FluidConfig:
    return FluidConfig(
        dim=2, spacing=dx, pressure_solver=solver, depth_2d=SEEDED_DEPTH, max_expected_speed=2.0 * math.sqrt(2.0 * GRAVITY * top),
        domain_min=(-0.1, -0.1, -0.02), domain_max=(0.1, 0.1, top + 0.05), **numerics,
    )


@dataclass(frozen=True)
class Caught:
    """The resting column: its height (m, twice the particles' mean height above the floor: the centroid of a
    level column is at half its height) against V / (d w), and the vessel's mean vertical force (N) against
    rho0 g V."""

    height: float
    reference_height: float
    weight: float
    reference_weight: float
    masses: np.ndarray
    seeded_mass: float
    volume_in_tank: float
    volume: float


def drop_into_deeper_tank(solver: str, across: int, **numerics) -> Caught:
    """A block of liquid seeded for SEEDED_DEPTH above a tank TANK_DEPTH deep, as tall as V / (SEEDED_DEPTH w) so
    that it would stand TANK_DEPTH / SEEDED_DEPTH = 1.4 times too high if it kept its depth, dropped from the rim
    (2 dx narrower than the tank on each side, so no particle lands on a wall's top), left to settle."""
    dx = TANK_WIDTH / across
    tank = VesselSpec(name="tank", inner_width=TANK_WIDTH, inner_depth=TANK_DEPTH, inner_height=2.0 * COLUMN)
    block_width = TANK_WIDTH - 4.0 * dx
    seeded_height = COLUMN * TANK_DEPTH / SEEDED_DEPTH * TANK_WIDTH / block_width
    bottom = tank.inner_height + 2.0 * dx
    cfg = _config(solver, dx, bottom + seeded_height, **numerics)
    block = liquid_block((-0.5 * block_width, -0.05, bottom), (0.5 * block_width, 0.05, bottom + seeded_height), cfg)
    fluid = FluidSolver(cfg, [tank], [Pose()], block)
    volume = len(block) * cfg.particle_volume
    forces = []
    while fluid.time < SETTLE - 1e-9:
        fluid.advance(INTERVAL)
        if fluid.time > SETTLE - AVERAGE + 1e-9:
            forces.append(-fluid.vessel_wrenches()[0, 2])
    z = fluid.positions()[:, 2]
    return Caught(
        height=2.0 * float(z.mean()), reference_height=volume / (TANK_DEPTH * TANK_WIDTH), weight=float(np.mean(forces)),
        reference_weight=cfg.rest_density * GRAVITY * volume, masses=fluid.masses(), seeded_mass=cfg.particle_mass, volume_in_tank=fluid.last_report.last.volume_in_vessel[0],
        volume=volume,
    )


# The default (the signal velocity with one alpha) lets the dropped block land loose; it closes because the divergence
# solve lets liquid below rest density compress (docs/divergence_constraint.md). c0 with the free liquid's alpha 0.25
# lands it in one piece and packs it even where the divergence solve removes every compressing rate: the former
# default's numerics, with its free-liquid rule.
SOUND_SPEED_EVERY_COMPRESSION = {"artificial_viscosity_scale": "sound_speed", "free_artificial_viscosity": 0.25, "divergence_constraint": "every_compression",
                                 "free_liquid_rule": "outside_vessels"}


CAUGHT = [
    ("dfsph", {}),
    # Under the free-liquid rule 'outside_vessels' the Jacobi iteration's landing splashed 2 of the particles over
    # the rim; under DFSPH's default rule, 'free_surface', none (docs/free_surface.md)
    ("dfsph", {"density_iteration": "jacobi"}),
    ("dfsph", SOUND_SPEED_EVERY_COMPRESSION),
    ("dfsph", {"particle_shifting": "fickian"}),
    ("wcsph", {}),
]
CAUGHT_IDS = ["dfsph", "dfsph-jacobi", "dfsph-sound-speed-every-compression", "dfsph-shifting", "wcsph"]


@functools.cache
def _caught(solver: str, numerics: tuple[tuple[str, object], ...]) -> Caught:
    """:func:`drop_into_deeper_tank` at 20 across, run once for both tests below."""
    return drop_into_deeper_tank(solver, 20, **dict(numerics))


@pytest.mark.parametrize(("solver", "numerics"), CAUGHT, ids=CAUGHT_IDS)
def test_caught_liquid_takes_the_tank_depth_stays_in_it_and_weighs_its_volume(solver, numerics):
    caught = _caught(solver, tuple(numerics.items()))
    np.testing.assert_array_equal(caught.masses, np.float32(caught.seeded_mass * SEEDED_DEPTH / TANK_DEPTH))
    assert caught.volume_in_tank == pytest.approx(caught.volume, rel=1e-12)
    assert abs(caught.weight / caught.reference_weight - 1.0) <= WEIGHT_TOLERANCE, caught


# WCSPH's default (no tension, Fourtakas et al.'s density diffusion read at the pressure's density; one alpha with
# Monaghan's beta = 2) stands short beyond the tolerance, as the former default (the 1 kPa clamp) did: its interior
# packs closer than the tank's lattice, as every WCSPH variant's does (docs/wcsph_knobs.md, "Where the height goes";
# docs/density_diffusion.md). A known failure, reported as one: strict, so that it reports when it starts passing.
HEIGHT_XFAIL = {"wcsph": "WCSPH's default caught column stands short of V / (d w) (docs/density_diffusion.md)"}


@pytest.mark.parametrize(
    ("solver", "numerics"),
    [pytest.param(*row, id=key, marks=[pytest.mark.xfail(strict=True, reason=HEIGHT_XFAIL[key])] if key in HEIGHT_XFAIL else [])
     for row, key in zip(CAUGHT, CAUGHT_IDS)],
)
def test_caught_liquid_stands_at_its_volume_over_the_tank_section(solver, numerics):
    caught = _caught(solver, tuple(numerics.items()))
    assert abs(caught.height / caught.reference_height - 1.0) <= HEIGHT_TOLERANCE, caught


def test_liquid_keeps_its_seeded_depth_until_it_enters_a_vessel():
    """Liquid seeded inside a vessel of another depth never entered it: it keeps the mass it was seeded with (the
    depth_2d of the scene), as before the per-particle depth."""
    dx = TANK_WIDTH / 12
    tank = VesselSpec(name="tank", inner_width=TANK_WIDTH, inner_depth=TANK_DEPTH, inner_height=2.0 * COLUMN)
    cfg = _config("dfsph", dx, tank.inner_height)
    fluid = FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, COLUMN, cfg))
    for _ in range(5):
        fluid.advance(INTERVAL)
    np.testing.assert_array_equal(fluid.masses(), np.float32(cfg.particle_mass))


def test_in_plane_mass_of_each_vessel():
    pourer = VesselSpec(name="pourer", inner_width=0.1, inner_depth=SEEDED_DEPTH, inner_height=0.1)
    catcher = VesselSpec(name="catcher", inner_width=0.26, inner_depth=TANK_DEPTH, inner_height=0.16)
    cfg = _config("dfsph", 0.005, 0.2)
    assert caught_liquid_mass(cfg, pourer) == cfg.particle_mass  # exactly: the pourer's liquid never changes
    assert caught_liquid_mass(cfg, catcher) == pytest.approx(cfg.rest_density * 0.005**2 * SEEDED_DEPTH / TANK_DEPTH, rel=1e-12)
    assert densest_smoothing_ratio(cfg, (pourer, catcher)) == pytest.approx(cfg.smoothing_ratio * math.sqrt(TANK_DEPTH / SEEDED_DEPTH), rel=1e-12)
    assert densest_smoothing_ratio(cfg, (pourer,)) == cfg.smoothing_ratio
    shallower = VesselSpec(name="shallow", inner_width=0.1, inner_depth=0.05, inner_height=0.1)
    assert densest_smoothing_ratio(cfg, (pourer, shallower)) == cfg.smoothing_ratio  # a shallower vessel: a heavier, sparser liquid
    three_d = FluidConfig(dim=3, spacing=0.005)
    assert caught_liquid_mass(three_d, catcher) == 0.0  # a 3-D particle is a volume: nothing to spread
    no_free = _config("wcsph", 0.005, 0.2, free_liquid=False)
    assert caught_liquid_mass(no_free, catcher) == 0.0
