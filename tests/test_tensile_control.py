"""WCSPH's tensile-instability control (``FluidConfig.tension_treatment`` 'tic', Sun et al. 2018, Eq. 9): the pair
factor's four branches, and a liquid block in uniform tension whose interior feels no force from its particles'
disorder under the control, but does under the symmetric sum."""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from cosim.fluid.config import FluidConfig
from cosim.fluid.seeding import ParticleSet, liquid_block
from cosim.fluid.solver import FluidSolver
from cosim.fluid.wcsph import TIC_SURFACE_REGION, own_pressure, pressure_pair_factor

RHO_I, RHO_J = 990.0, 1010.0  # kg/m^3
DX = 0.005  # m
STEP = 1.0e-4  # s: one substep at this configuration (its planned step is longer)


@wp.kernel
def _pair_factors(
    tic: int, p_i: wp.array(dtype=float), indicator: wp.array(dtype=float), p_j: float, rho_i: float, rho_j: float,
    wall: int, out: wp.array(dtype=float),
):
    k = wp.tid()
    own = own_pressure(tic, p_i[k], indicator[k])
    if wall != 0:
        own = wp.max(own, 0.0)
    out[k] = pressure_pair_factor(tic, own, rho_i, p_j, rho_j)


def _factor(tic: int, p_i: float, indicator: float, p_j: float, wall: bool = False) -> float:
    out = wp.zeros(1, dtype=float, device="cpu")
    wp.launch(_pair_factors, 1, inputs=[tic, wp.array([p_i], dtype=float, device="cpu"), wp.array([indicator], dtype=float, device="cpu"),
                                        p_j, RHO_I, RHO_J, int(wall), out], device="cpu")
    return float(out.numpy()[0])


@pytest.mark.parametrize("p_i, indicator, expected_f", [
    (300.0, 1.0, lambda pi, pj: pi + pj),  # compression: the plus form
    (-300.0, 0.5, lambda pi, pj: pi + pj),  # tension at the free surface (its region): the plus form
    (-300.0, TIC_SURFACE_REGION, lambda pi, pj: pi + pj),  # the region's edge belongs to it
    (-300.0, 1.0, lambda pi, pj: pj - pi),  # tension inside the liquid: the minus form
])
def test_the_control_switches_on_the_particles_own_pressure_and_region(p_i, indicator, expected_f):
    p_j = -120.0
    got = _factor(1, p_i, indicator, p_j)
    assert got == pytest.approx(expected_f(p_i, p_j) / (RHO_I * RHO_J), rel=1e-6)
    # the neighbour's pressure never chooses the branch
    assert _factor(1, p_i, indicator, 500.0) == pytest.approx(expected_f(p_i, 500.0) / (RHO_I * RHO_J), rel=1e-6)


def test_without_the_control_the_factor_is_monaghans_symmetric_sum():
    assert _factor(0, -300.0, 1.0, -120.0) == pytest.approx(-300.0 / RHO_I**2 - 120.0 / RHO_J**2, rel=1e-6)


def test_walls_only_push_a_particle_in_tension_at_the_surface_but_push_harder_inside():
    # wall pairs take max(own pressure, 0): at the surface a particle's tension does not pull it onto the wall,
    # inside the liquid the minus form's -p_i pushes as the neighbours' (p_j - p_i) do
    p_b = 50.0
    assert _factor(1, -300.0, 0.5, p_b, wall=True) == pytest.approx(p_b / (RHO_I * RHO_J), rel=1e-6)
    assert _factor(1, -300.0, 1.0, p_b, wall=True) == pytest.approx((p_b + 300.0) / (RHO_I * RHO_J), rel=1e-6)


def _block_in_tension(treatment: str) -> tuple[FluidSolver, np.ndarray]:
    """A 2-D block in the air, its lattice jittered by up to 0.15 dx, every particle at 0.995 rho0 (about -0.5 kPa,
    no clamp), after one substep from rest; and each particle's indicator."""
    cfg = FluidConfig(dim=2, spacing=DX, pressure_solver="wcsph", max_expected_speed=1.0, free_liquid=False,
                      tension_treatment=treatment, max_tension=1.0e6, domain_min=(-0.3, -0.3, -0.3), domain_max=(0.3, 0.3, 0.3))
    block = liquid_block((-0.04, -0.05, 0.0), (0.04, 0.05, 0.08), cfg)
    rng = np.random.default_rng(7)
    jitter = rng.uniform(-0.15 * DX, 0.15 * DX, block.positions.shape)
    jitter[:, 1] = 0.0
    particles = ParticleSet(block.positions + jitter, block.velocities, np.full(len(block), 0.995 * cfg.rest_density))
    solver = FluidSolver(cfg, [], [], particles)
    assert solver.pressures().max() < -400.0
    solver.advance(STEP)
    return solver, solver.free_surface_indicator()


def test_a_block_in_uniform_tension_feels_no_clumping_force_inside_under_the_control():
    g = FluidConfig.gravity[2]
    solver, lam = _block_in_tension("tic")
    v = solver.velocities()
    inside = lam > TIC_SURFACE_REGION
    assert inside.sum() > 100
    # uniform pressure and density, at rest: each pair's p_j - p_i is zero, so only gravity acts
    assert np.abs(v[inside, 0]).max() < 1e-6
    assert np.abs(v[inside, 2] - g * STEP).max() < 1e-6
    # the surface keeps the plus form: its tension pulls it in (the top row down, faster than gravity alone)
    top = solver.positions()[:, 2] > solver.positions()[:, 2].max() - 0.5 * DX
    assert (v[top & ~inside, 2] < g * STEP - 1e-4).all()


@pytest.mark.parametrize("treatment", ["clamp", "symmetric"])
def test_the_symmetric_sum_pushes_the_disordered_interior_of_a_block_in_tension(treatment):
    solver, _ = _block_in_tension(treatment)
    v = solver.velocities()
    x = solver.positions()
    middle = (np.abs(x[:, 0]) < 0.02) & (np.abs(x[:, 2] - 0.04) < 0.02)
    # 2 p / rho sum_j V_j grad W over a jittered support: the tensile term the control removes (m/s after one step)
    assert np.abs(v[middle, 0]).max() > 1e-3


@pytest.mark.parametrize("treatment, floor", [("clamp", -1000.0), ("symmetric", None), ("tic", None)])
def test_only_the_clamp_treatment_clamps_the_tension(treatment, floor):
    cfg = FluidConfig(dim=2, spacing=DX, pressure_solver="wcsph", max_expected_speed=1.0, tension_treatment=treatment,
                      max_tension=1000.0, domain_min=(-0.3, -0.3, -0.3), domain_max=(0.3, 0.3, 0.3))
    block = liquid_block((-0.02, -0.05, 0.0), (0.02, 0.05, 0.02), cfg)
    stretched = ParticleSet(block.positions, block.velocities, np.full(len(block), 0.98 * cfg.rest_density))
    tait = cfg.rest_density * cfg.sound_speed**2 / cfg.gamma * (0.98**cfg.gamma - 1.0)  # about -1.9 kPa
    expected = tait if floor is None else max(tait, floor)
    assert FluidSolver(cfg, [], [], stretched).pressures() == pytest.approx(expected, rel=1e-4)


def test_the_unclamped_symmetric_sum_is_the_clamp_never_reached():
    # the Tait tension at the integration's density floor (0.8 rho0) is about -0.8 rho0 c0^2 / gamma, well inside the
    # clamp's largest allowed 1 MPa here, so the two treatments run the same substeps
    runs = []
    for kw in ({"tension_treatment": "symmetric"}, {"tension_treatment": "clamp", "max_tension": 1.0e6}):
        cfg = FluidConfig(dim=2, spacing=DX, pressure_solver="wcsph", max_expected_speed=1.0, domain_min=(-0.3, -0.3, -0.3),
                          domain_max=(0.3, 0.3, 0.3), **kw)
        block = liquid_block((-0.02, -0.05, 0.0), (0.02, 0.05, 0.04), cfg)
        solver = FluidSolver(cfg, [], [], ParticleSet(block.positions, block.velocities, np.full(len(block), 0.98 * cfg.rest_density)))
        solver.advance(10 * STEP)
        runs.append((solver.positions(), solver.pressures()))
    assert cfg.rest_density * cfg.sound_speed**2 / cfg.gamma * 0.8 < 1.0e6
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    np.testing.assert_array_equal(runs[0][1], runs[1][1])
