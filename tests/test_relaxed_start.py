"""fluid.initial_state, under DFSPH's seeded offsets (surface_density 'seeded_offset'; the continuity surface:
tests/test_surface_density.py): 'seeded' keeps the seeded kernel deficiency as DFSPH's per-particle rest offset and
starts as seeded; 'relaxed' settles the liquid in its vessel, held still, until it stops moving (or a time cap), with no
offset, and the run starts there at rest, no particle compressed beyond the solve's per-particle bound."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cosim.fluid.config import GRAVITY, FluidConfig, InitialState, SurfaceDensity
from cosim.fluid.dfsph import MAX_PARTICLE_RESIDUAL
from cosim.fluid.relaxation import AT_REST, RELAX_INTERVAL, RELAX_TIME_CAP, STALLED, TIME_CAP, stop_speed
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.vessel import VesselSpec

WIDTH = 0.06  # m, a small box tank: 12 particles across
SPACING = 0.005  # m
FILL = 0.04  # m, 8 layers


def _tank(state: InitialState | None, **solver_args) -> FluidSolver:
    tank = VesselSpec(name="tank", inner_width=WIDTH, inner_depth=0.1, inner_height=0.08)
    fields = {} if state is None else {"initial_state": state}
    cfg = FluidConfig(dim=2, spacing=SPACING, max_expected_speed=2 * math.sqrt(GRAVITY * FILL), domain_min=(-0.1, -0.1, -0.05),
                      domain_max=(0.1, 0.1, 0.15), cpu_threads=1, surface_density=SurfaceDensity.SEEDED_OFFSET, **fields)
    return FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, FILL, cfg), **solver_args)


def _offsets(solver: FluidSolver) -> np.ndarray:
    """kg/m^3, each particle's DFSPH rest offset, in the particles' original order."""
    out = np.empty(solver.n_particles)
    out[solver.state.pid.numpy()] = solver.state.rest_offset.numpy()
    return out


def test_seeded_is_the_default_and_keeps_the_seeded_offsets():
    assert FluidConfig().initial_state is InitialState.SEEDED
    solver = _tank(None)
    seeded = solver.positions()
    assert solver.relaxation is None and solver.time == 0.0 and solver.step_count == 0
    solver.advance(RELAX_INTERVAL)
    offsets, z = _offsets(solver), seeded[:, 2]
    top = z > z.max() - 0.5 * SPACING
    assert offsets[top].min() > 0.1 * solver.config.rest_density  # the top row is held at its seeded kernel deficiency
    assert offsets[z < FILL / 2].max() < 0.01 * solver.config.rest_density


def test_relaxation_stops_by_its_speed_criterion_and_starts_the_run_at_rest():
    solver = _tank(InitialState.RELAXED)
    report = solver.relaxation
    assert report.outcome == AT_REST and report.converged and report.last_speed < stop_speed(GRAVITY)
    assert 1 < report.intervals < RELAX_TIME_CAP / RELAX_INTERVAL and report.substeps >= report.intervals
    assert report.settle_time == pytest.approx(report.intervals * RELAX_INTERVAL)
    assert solver.time == 0.0 and solver.step_count == 0 and solver.history() == {}
    assert not solver.velocities().any()
    assert solver.energy_account.created == 0.0
    assert not _offsets(solver).any()  # no per-particle offset on the relaxed path


def test_relaxation_reports_a_time_cap_or_a_stall_reached_before_its_criterion():
    solver = _tank(InitialState.RELAXED, relax_start=False)
    assert solver.relaxation is None
    capped = solver.relax(2 * RELAX_INTERVAL, RELAX_INTERVAL, stop=1e-9)
    assert capped.outcome == TIME_CAP and not capped.converged and capped.intervals == 2 and capped.last_speed >= 1e-9
    stalled = _tank(InitialState.RELAXED, relax_start=False).relax(RELAX_TIME_CAP, RELAX_INTERVAL, stop=1e-9, stall=2 * RELAX_INTERVAL)
    assert stalled.outcome == STALLED and stalled.intervals < RELAX_TIME_CAP / RELAX_INTERVAL


def _rms_speed_after(solver: FluidSolver, intervals: int) -> float:
    """m/s, the liquid's rms speed after ``intervals`` intervals of the resting tank."""
    for _ in range(intervals):
        solver.advance(RELAX_INTERVAL)
    return float(np.sqrt((solver.velocities() ** 2).sum(axis=1).mean()))


def test_relaxed_tank_rests_at_rest_density_and_starts_calmer_than_the_seeded_one():
    """After the relaxation the resting tank keeps no particle compressed above the density solve's per-particle
    bound, stays where it settled, and moves less in its first 50 ms than the seeded start (whose offsets hold
    the seeded lattice, which the compression-only solve leaves with a residual motion)."""
    solver = _tank(InitialState.RELAXED)
    relaxed = solver.positions()
    speed = _rms_speed_after(solver, 25)
    assert solver.history()["max_compression"].max() <= MAX_PARTICLE_RESIDUAL
    assert solver.densities().max() <= (1.0 + MAX_PARTICLE_RESIDUAL) * solver.config.rest_density
    assert np.abs(solver.positions() - relaxed).max() < 0.05 * SPACING
    assert speed < _rms_speed_after(_tank(InitialState.SEEDED), 25)


def test_initial_state_is_a_declared_setting_of_scenes_and_validation_numerics():
    from cosim.pour_scene import FluidSettings
    from cosim.validation.common import NUMERICS_FIELDS

    assert FluidSettings().fluid_config(0.191).initial_state is InitialState.SEEDED
    assert dataclasses.replace(FluidSettings(), initial_state=InitialState.RELAXED).fluid_config(0.191).initial_state is InitialState.RELAXED
    assert "initial_state" in NUMERICS_FIELDS


def test_an_unknown_initial_state_is_refused_naming_the_field():
    from cosim.errors import InputError

    with pytest.raises(InputError, match="initial_state"):
        FluidConfig(initial_state="settled")
