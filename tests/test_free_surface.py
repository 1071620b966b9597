"""Free-surface detection (cosim.fluid.free_surface, Marrone et al. 2010) against the analytic sums over a square
(cubic) lattice, and the 'free_surface' free-liquid rule: its state changes, and that it needs no vessel."""

from __future__ import annotations

import math

import numpy as np
import pytest
import warp as wp

from cosim.fluid.config import FluidConfig
from cosim.fluid.free_surface import FREE_AT_SURFACE, exposed_liquid, smallest_eigenvalue_3d
from cosim.fluid.boundary import VesselGeometry, VesselMotion
from cosim.fluid.params import SPHParams
from cosim.fluid.seeding import ParticleSet, fill_vessel, liquid_block
from cosim.fluid.solver import FluidSolver
from cosim.fluid.sph_common import next_free_state
from cosim.frames import Pose
from cosim.vessel import VesselSpec

SMOOTHING_RATIO = FluidConfig.smoothing_ratio  # h / dx; the lattice sums below use the default Wendland C2 kernel
LATTICE_TOLERANCE = 1.0e-3  # the solver's float32 sums against the float64 lattice sums
DX = 0.005  # m


def lattice_indicator(dim: int, rows_above: int | None) -> float:
    """Marrone's lambda of a particle in a resting square (cubic) lattice of unit spacing that ends ``rows_above``
    rows above it (None: unbounded), Wendland C2 at h = SMOOTHING_RATIO: the smallest eigenvalue of
    -sum_j (x_i - x_j) (x) grad W_ij V_j, V_j = 1, summed here in float64 from the kernel's own formula."""
    h = SMOOTHING_RATIO
    reach = math.ceil(2.0 * h)
    axis = np.arange(-reach, reach + 1, dtype=float)
    offsets = np.stack(np.meshgrid(*([axis] * dim), indexing="ij"), axis=-1).reshape(-1, dim)  # x_j - x_i
    if rows_above is not None:
        offsets = offsets[offsets[:, -1] <= rows_above]
    r = np.linalg.norm(offsets, axis=1)
    keep = (r > 0.0) & (r < 2.0 * h)
    offsets, r = offsets[keep], r[keep]
    q = r / h
    sigma = 7.0 / (4.0 * math.pi * h**2) if dim == 2 else 21.0 / (16.0 * math.pi * h**3)
    slope = sigma * (-5.0 * q * (1.0 - 0.5 * q) ** 3) / h  # dW/dr
    grad_i = (slope / r)[:, None] * (-offsets)  # grad_i W_ij, along x_i - x_j
    matrix = np.einsum("ja,jb->ab", offsets, grad_i)  # -(x_i - x_j) (x) grad_i W_ij = (x_j - x_i) (x) grad_i W_ij
    return float(np.linalg.eigvalsh(matrix)[0])


def test_the_lattice_sums_give_marrones_values():
    # the interior is the identity's 1, a flat surface's top row about half of it (Marrone et al. 2010)
    assert lattice_indicator(2, None) == pytest.approx(1.0, abs=0.005)
    assert lattice_indicator(3, None) == pytest.approx(1.0, abs=0.005)
    assert lattice_indicator(2, 0) == pytest.approx(0.5, abs=0.005)
    assert lattice_indicator(3, 0) == pytest.approx(0.5, abs=0.005)
    assert 0.75 < lattice_indicator(2, 1) < 0.9  # the second row: above Marrone's scan region (0.75)


def _indicator_after_one_step(cfg: FluidConfig, particles: ParticleSet, vessels=(), poses=()) -> FluidSolver:
    solver = FluidSolver(cfg, list(vessels), list(poses), particles)
    solver.advance(1.0e-4)  # one substep: the indicator is measured at its start, on the lattice as seeded
    return solver


def _air_config(dim: int, solver: str) -> FluidConfig:
    return FluidConfig(dim=dim, spacing=DX, pressure_solver=solver, max_expected_speed=1.0, free_liquid_rule="free_surface",
                       domain_min=(-0.3, -0.3, -0.3), domain_max=(0.3, 0.3, 0.3))


@pytest.mark.parametrize("solver", ["wcsph", "dfsph"])
def test_a_resting_block_in_2d_has_the_lattice_values_and_a_lone_particle_zero(solver):
    cfg = _air_config(2, solver)
    block = liquid_block((-0.05, -0.05, 0.0), (0.05, 0.05, 0.06), cfg)
    lone = ParticleSet(np.array([[0.2, 0.0, 0.1]]), np.zeros((1, 3)), np.full(1, cfg.rest_density))
    lam = _indicator_after_one_step(cfg, ParticleSet.concatenate([block, lone])).free_surface_indicator()
    x, z = block.positions[:, 0], block.positions[:, 2]
    middle = np.abs(x) < 0.03  # away from the block's sides (more than a support)
    top = np.isclose(z, z.max())
    second = np.isclose(z, z.max() - DX)
    inside = (z > z.min() + 3 * DX) & (z < z.max() - 3 * DX)
    for rows, where in ((0, top), (1, second), (None, inside)):
        assert lam[:-1][middle & where] == pytest.approx(lattice_indicator(2, rows), abs=LATTICE_TOLERANCE)
    assert lam[-1] == 0.0


def test_a_tilted_cube_in_3d_has_the_lattice_values():
    # tilted about an oblique axis, so the eigenvalue comes from a full 3x3 matrix (off-diagonal terms)
    cfg = _air_config(3, "dfsph")
    n = 10
    block = liquid_block((-0.5 * n * DX,) * 2 + (0.0,), (0.5 * n * DX,) * 2 + (n * DX,), cfg)
    local = block.positions - block.positions.mean(axis=0)
    axis = np.array([1.0, 2.0, 0.5]) / np.linalg.norm([1.0, 2.0, 0.5])
    angle = 0.6
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rotation = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
    tilted = ParticleSet(local @ rotation.T, np.zeros_like(local), block.densities)
    lam = _indicator_after_one_step(cfg, tilted).free_surface_indicator()
    reach = 3.5 * DX  # more than a support (3 dx) from the faces it is not measured against
    top = np.isclose(local[:, 2], local[:, 2].max()) & (np.abs(local[:, :2]) < 0.5 * n * DX - reach).all(axis=1)
    inside = (np.abs(local) < 0.5 * n * DX - reach).all(axis=1)
    assert top.sum() > 0 and inside.sum() > 0
    assert lam[top] == pytest.approx(lattice_indicator(3, 0), abs=LATTICE_TOLERANCE)
    assert lam[inside] == pytest.approx(lattice_indicator(3, None), abs=LATTICE_TOLERANCE)


@wp.kernel
def _smallest_eigenvalues(matrices: wp.array(dtype=wp.mat33), out: wp.array(dtype=float)):
    i = wp.tid()
    out[i] = smallest_eigenvalue_3d(matrices[i])


def test_the_closed_form_3x3_eigenvalue_matches_numpy():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(200, 3, 3))
    symmetric = np.concatenate([a + a.transpose(0, 2, 1), np.eye(3)[None] * [[[2.0]]], np.diag([0.2, 0.5, 0.5])[None],
                                np.zeros((1, 3, 3))])
    out = wp.zeros(len(symmetric), dtype=float, device="cpu")
    wp.launch(_smallest_eigenvalues, len(symmetric), inputs=[wp.array(symmetric.astype(np.float32), dtype=wp.mat33, device="cpu"), out],
              device="cpu")
    np.testing.assert_allclose(out.numpy(), np.linalg.eigvalsh(symmetric)[:, 0], atol=2e-5 * np.abs(symmetric).max())


def test_walls_count_as_neighbours_so_liquid_against_them_is_inside():
    tank = VesselSpec(name="tank", inner_width=0.191, inner_height=0.2)
    cfg = FluidConfig(dim=2, spacing=0.191 / 16, pressure_solver="dfsph", max_expected_speed=2.0, free_liquid_rule="free_surface",
                      domain_min=(-0.2, -0.15, -0.1), domain_max=(0.2, 0.15, 0.35), wall_model="kernel_layers")  # the lattice continued
    solver = _indicator_after_one_step(cfg, fill_vessel(tank, 0.1, cfg), [tank], [Pose()])
    lam, z = solver.free_surface_indicator(), solver.positions()[:, 2]
    below_surface = z < z.max() - 1.5 * cfg.spacing  # every row but the top two, the floor's and the walls' own included
    assert lam[below_surface] == pytest.approx(lattice_indicator(2, None), abs=LATTICE_TOLERANCE)


@wp.kernel
def _next_states(
    prm: SPHParams,
    free_now: wp.array(dtype=wp.int32), indicator: wp.array(dtype=float), summation: wp.array(dtype=float), threshold: float,
    vessels: wp.array(dtype=VesselGeometry), motions: wp.array(dtype=VesselMotion), out: wp.array(dtype=wp.int32),
):
    i = wp.tid()
    exposed = exposed_liquid(prm, vessels, motions, FREE_AT_SURFACE, wp.vec3(0.0), indicator[i], threshold)
    out[i] = next_free_state(free_now[i], exposed, summation[i], 1000.0)


@pytest.mark.parametrize(
    "free_now, indicator, summation, expected",
    [
        (0, 0.1, 900.0, 1),  # at the surface and separated: free
        (0, 0.1, 1010.0, 0),  # at the surface but packed: stays bound
        (0, 0.9, 900.0, 0),  # separated but inside the liquid: stays bound
        (1, 0.9, 1000.0, 0),  # inside the liquid and packed: bound again
        (1, 0.1, 1010.0, 1),  # packed but still at the surface: stays free
        (1, 0.9, 950.0, 1),  # inside but not packed: stays free
    ],
)
def test_the_free_surface_rule_changes_state_at_the_surface_and_when_packed(free_now, indicator, summation, expected):
    args = [SPHParams(), wp.array([free_now], dtype=wp.int32), wp.array([indicator], dtype=float), wp.array([summation], dtype=float), 0.5,
            wp.zeros(0, dtype=VesselGeometry), wp.zeros(0, dtype=VesselMotion)]
    out = wp.zeros(1, dtype=wp.int32)
    wp.launch(_next_states, 1, inputs=[*args, out], device="cpu")
    assert int(out.numpy()[0]) == expected


def _drop_over_a_pool(solver: str, rule: str | None) -> tuple[FluidConfig, np.ndarray]:
    """A drop inside a tall tank, above its resting pool and below its rim, after one substep: (config, free mask;
    the drop last)."""
    tank = VesselSpec(name="tank", inner_width=0.191, inner_height=0.4)
    cfg = FluidConfig(dim=2, spacing=0.191 / 16, pressure_solver=solver, max_expected_speed=2.0, free_liquid_rule=rule,
                      domain_min=(-0.2, -0.15, -0.1), domain_max=(0.2, 0.15, 0.5))
    pool = fill_vessel(tank, 0.06, cfg)
    drop = ParticleSet(np.array([[0.0, 0.0, 0.3]]), np.zeros((1, 3)), np.full(1, cfg.rest_density))
    return cfg, _indicator_after_one_step(cfg, ParticleSet.concatenate([pool, drop]), [tank], [Pose()]).free_mask()


@pytest.mark.parametrize("rule, drop_is_free", [("free_surface", True), ("outside_vessels", False)])
def test_the_free_surface_rule_needs_no_vessel(rule, drop_is_free):
    # the drop is free at the surface by the local rule, bound by the geometric one (it is inside a vessel); the
    # resting pool is bound either way, its surface row too (lambda 0.5, above the default threshold)
    cfg, free = _drop_over_a_pool("wcsph", rule)
    assert free[-1] == drop_is_free
    assert cfg.free_surface_threshold < lattice_indicator(2, 0)
    assert not free[:-1].any()


@pytest.mark.parametrize("solver, rule", [("dfsph", "free_surface"), ("wcsph", "free_surface")])
def test_an_unset_rule_is_the_pressure_solvers_own(solver, rule):
    # both solvers' default is the local rule: the drop inside the tank is free, the pool bound; a rule that is set
    # is the one in effect under either solver
    cfg, free = _drop_over_a_pool(solver, None)
    assert cfg.free_liquid_rule is None and cfg.free_liquid_rule_in_effect.value == rule
    assert free[-1] == (rule == "free_surface")
    assert not free[:-1].any()
    other = "outside_vessels" if rule == "free_surface" else "free_surface"
    assert FluidConfig(spacing=0.01, pressure_solver=solver, free_liquid_rule=other).free_liquid_rule_in_effect.value == other
