"""Particle shifting (cosim.fluid.shifting): down the concentration gradient into a void, none at the free surface or
against a wall, along them near them; nothing is allocated or launched when it is off."""

from __future__ import annotations

import numpy as np
import pytest

from cosim.fluid.config import FluidConfig
from cosim.fluid.seeding import ParticleSet, fill_vessel, liquid_block
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.vessel import VesselSpec

DX = 0.005  # m
LATTICE_NOISE = 1.0e-4  # of the largest shift: what float32 sums leave of a shift that is zero on a symmetric lattice


def _one_substep(cfg: FluidConfig, particles: ParticleSet, vessels=(), poses=()):
    """The solver after one substep, with the positions it started from (m, in the substep's cell order, the order
    of the shift's arrays) and its shifts (m)."""
    solver = FluidSolver(cfg, list(vessels), list(poses), particles)
    start = solver.positions()
    solver.advance(1.0e-4)  # one substep
    n = solver.model.n_particles
    order = solver.state.pid.numpy()[:n]
    sc = solver.scratch.shifting
    return start[order], sc.shift.numpy()[:n].astype(np.float64), sc.indicator.numpy()[:n]


def _air_config(solver: str, shifting: str = "fickian") -> FluidConfig:
    return FluidConfig(dim=2, spacing=DX, pressure_solver=solver, max_expected_speed=1.0, particle_shifting=shifting,
                       domain_min=(-0.3, -0.3, -0.3), domain_max=(0.3, 0.3, 0.3))


@pytest.mark.parametrize("solver", ["wcsph", "dfsph"])
def test_particles_shift_into_a_void_and_not_out_of_the_free_surface(solver):
    cfg = _air_config(solver)
    block = liquid_block((-0.05, -0.05, 0.0), (0.05, 0.05, 0.06), cfg)
    hole = block.positions[np.argmin(np.linalg.norm(block.positions - [0.0, 0.0, 0.03], axis=1))]  # a particle removed
    keep = np.linalg.norm(block.positions - hole, axis=1) > 0.1 * DX
    assert (~keep).sum() == 1
    x, shift, lam = _one_substep(cfg, ParticleSet(block.positions[keep], block.velocities[keep], block.densities[keep]))
    largest = np.abs(shift).max()
    to_hole = hole - x
    ring = np.isclose(np.linalg.norm(to_hole, axis=1), DX, rtol=1e-3)  # the hole's four nearest neighbours
    assert ring.sum() == 4
    inward = np.einsum("ij,ij->i", shift[ring], to_hole[ring]) / DX
    assert (inward > 0.9 * np.linalg.norm(shift[ring], axis=1)).all()  # each moves toward the hole
    surface = lam < 0.75
    assert surface.sum() > 0
    assert (shift[surface] == 0.0).all()  # none in the free-surface region
    top = x[:, 2].max()
    second_row = np.isclose(x[:, 2], top - DX) & (np.abs(x[:, 0]) < 0.03)
    assert np.abs(shift[second_row, 2]).max() <= LATTICE_NOISE * largest  # near the flat surface: along it only
    far = (np.linalg.norm(to_hole, axis=1) > 3.5 * DX) & (x[:, 2] < top - 3.5 * DX) & (x[:, 2] > 3.5 * DX) & (np.abs(x[:, 0]) < 0.05 - 3.5 * DX)
    assert far.sum() > 0
    assert np.abs(shift[far]).max() <= LATTICE_NOISE * largest  # a uniform lattice: no gradient, no shift


def test_a_void_in_3d_is_filled_from_its_six_neighbours():
    cfg = FluidConfig(dim=3, spacing=DX, pressure_solver="dfsph", max_expected_speed=1.0, particle_shifting="fickian",
                      domain_min=(-0.1, -0.1, -0.1), domain_max=(0.1, 0.1, 0.1))
    block = liquid_block((-0.025, -0.025, 0.0), (0.025, 0.025, 0.05), cfg)
    hole = block.positions[np.argmin(np.linalg.norm(block.positions - [0.0, 0.0, 0.025], axis=1))]
    keep = np.linalg.norm(block.positions - hole, axis=1) > 0.1 * DX
    x, shift, lam = _one_substep(cfg, ParticleSet(block.positions[keep], block.velocities[keep], block.densities[keep]))
    to_hole = hole - x
    ring = np.isclose(np.linalg.norm(to_hole, axis=1), DX, rtol=1e-3)
    assert ring.sum() == 6
    inward = np.einsum("ij,ij->i", shift[ring], to_hole[ring]) / DX
    assert (inward > 0.9 * np.linalg.norm(shift[ring], axis=1)).all() and (inward > 0.0).all()
    assert (shift[lam < 0.75] == 0.0).all() and (lam < 0.75).sum() > 0


def test_liquid_against_a_wall_is_not_shifted_and_the_next_column_moves_along_it():
    # the liquid alone gives the indicator: the column touching a wall has a half support, like a free surface
    tank = VesselSpec(name="tank", inner_width=0.1, inner_height=0.1)
    cfg = FluidConfig(dim=2, spacing=DX, pressure_solver="wcsph", max_expected_speed=1.0, particle_shifting="fickian",
                      domain_min=(-0.2, -0.15, -0.1), domain_max=(0.2, 0.15, 0.25))
    particles = fill_vessel(tank, 0.05, cfg)
    # disordered, so that the concentration has a gradient everywhere
    jitter = np.random.default_rng(1).uniform(-0.03 * DX, 0.03 * DX, particles.positions.shape) * np.array([1.0, 0.0, 1.0])
    x, shift, _ = _one_substep(cfg, ParticleSet(particles.positions + jitter, particles.velocities, particles.densities), [tank], [Pose()])
    length = np.linalg.norm(shift, axis=1)
    below_surface = (x[:, 2] > 3.0 * DX) & (x[:, 2] < 0.05 - 3.0 * DX)
    gap = 0.05 - np.abs(x[:, 0])  # to the nearer side wall's face
    touching, next_column, inner = (below_surface & (np.abs(gap - k * DX) < 0.3 * DX) for k in (0.5, 1.5, 3.5))
    assert touching.sum() > 0 and next_column.sum() > 0 and inner.sum() > 0
    assert (shift[touching] == 0.0).all()
    assert (length[next_column] > 0.0).all()
    assert (np.abs(shift[next_column, 0]) <= 0.2 * length[next_column]).all()  # along the wall, to its own normal's tilt
    assert np.median(np.abs(shift[inner, 0]) / length[inner]) > 0.4  # away from the wall the shift goes every way


def test_shifting_off_allocates_and_launches_nothing():
    cfg = _air_config("dfsph", shifting="off")
    solver = FluidSolver(cfg, [], [], liquid_block((-0.02, -0.05, 0.0), (0.02, 0.05, 0.02), cfg))
    assert solver.scratch.shifting is None
