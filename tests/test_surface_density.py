"""fluid.surface_density: DFSPH's surface rows held to the density the continuity equation carries to them
('continuity', wherever Marrone's indicator is below 0.75) instead of a deficiency frozen at the seeding
('seeded_offset', the default)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cosim.fluid.config import GRAVITY, FluidConfig, InitialState, SurfaceDensity
from cosim.fluid.dfsph import FULL_SUPPORT_INDICATOR
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.vessel import VesselSpec

WIDTH = 0.06  # m, a small box tank: 12 particles across
SPACING = 0.005  # m
FILL = 0.04  # m, 8 layers


def _tank(surface: SurfaceDensity, state: InitialState) -> FluidSolver:
    tank = VesselSpec(name="tank", inner_width=WIDTH, inner_depth=0.1, inner_height=0.08)
    cfg = FluidConfig(dim=2, spacing=SPACING, max_expected_speed=2 * math.sqrt(GRAVITY * FILL), domain_min=(-0.1, -0.1, -0.05),
                      domain_max=(0.1, 0.1, 0.15), cpu_threads=1, surface_density=surface, initial_state=state)
    return FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, FILL, cfg))


def _in_id_order(solver: FluidSolver, array) -> np.ndarray:
    out = np.empty(solver.n_particles)
    out[solver.state.pid.numpy()] = array.numpy()
    return out


def _top_row_drop(solver: FluidSolver, duration: float) -> float:
    """m, how far the resting tank's top row (as it starts) sinks on average over ``duration``."""
    start = solver.positions()
    top = start[:, 2] > start[:, 2].max() - 0.5 * SPACING
    solver.advance(duration)
    return float((start[top, 2] - solver.positions()[top, 2]).mean())


def test_continuity_is_the_default():
    assert FluidConfig().surface_density is SurfaceDensity.CONTINUITY


def test_continuity_holds_the_relaxed_top_row_where_compression_alone_lets_it_sink():
    """Relaxed, with no seeded offset: the compression-only surface lets the top row sink into the gaps of the
    second; carried by continuity it keeps its spacing, as the seeded offset kept it."""
    held = _top_row_drop(_tank(SurfaceDensity.CONTINUITY, InitialState.RELAXED), 0.6)
    sunk = _top_row_drop(_tank(SurfaceDensity.SEEDED_OFFSET, InitialState.RELAXED), 0.6)
    assert abs(held) < 0.05 * SPACING
    assert sunk > 4 * abs(held)


def test_continuity_offsets_only_the_particles_short_of_a_full_support():
    solver = _tank(SurfaceDensity.CONTINUITY, InitialState.SEEDED)
    solver.advance(0.1)
    offset = _in_id_order(solver, solver.state.rest_offset)
    indicator = solver.free_surface_indicator()
    z = solver.positions()[:, 2]
    rho0 = solver.config.rest_density
    assert not offset[indicator >= FULL_SUPPORT_INDICATOR].any()
    top = z > z.max() - 0.5 * SPACING
    assert offset[top].min() > 0.1 * rho0  # the top row's kernel deficiency, about a quarter of rho0
    held = _in_id_order(solver, solver.state.rho)  # carried to the end of the last substep
    assert np.abs(held[top] / rho0 - 1.0).max() < 0.01


def test_surface_density_is_a_declared_setting_of_scenes_and_validation_numerics():
    from cosim.pour_scene import FluidSettings
    from cosim.validation.common import NUMERICS_FIELDS

    assert FluidSettings().fluid_config(0.191).surface_density is SurfaceDensity.CONTINUITY
    chosen = dataclasses.replace(FluidSettings(), surface_density=SurfaceDensity.SEEDED_OFFSET)
    assert chosen.fluid_config(0.191).surface_density is SurfaceDensity.SEEDED_OFFSET
    assert "surface_density" in NUMERICS_FIELDS


def test_an_unknown_surface_density_is_refused_naming_the_field():
    from cosim.errors import InputError

    with pytest.raises(InputError, match="surface_density"):
        FluidConfig(surface_density="summation")
