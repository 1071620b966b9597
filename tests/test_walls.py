"""The walls' dummy particles under each wall model (cosim.fluid.wall_sampling): ``real_thickness`` keeps every wall
particle inside the vessel's own wall, on the liquid's lattice continued into it, puts the crest at the real lip and
fits the volumes of a thin wall to the kernel sums of walls that cover the support; ``kernel_layers`` is
unchanged."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, PressureSolver, WallModel
from cosim.fluid.mesh_sampling import classify
from cosim.fluid.sph_kernels import kernel_values
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.sph_kernels import kernel_derivatives
from cosim.fluid.wall_sampling import (first_row_lattice, holds_a_layer, numerical_wall_thickness, one_layer_depth, sample_vessel_walls,
                                       slab_particles, wall_model_for)
from cosim.mesh_vessel import load_vessel_mesh
from cosim.pour_scene import FluidSettings
from cosim.vessel import VesselShape, VesselSpec, mesh_vessel_spec, seed_pouring_vessel
from tests.test_mesh_vessel import BEAKER

POURER = seed_pouring_vessel()
CUP = VesselSpec("cup", VesselShape.CYLINDER, 0.09, 0.09, 0.12, 0.004, 1180.0)
REAL = WallModel.REAL_THICKNESS


def real(spec: VesselSpec, across: int, dim: int) -> FluidConfig:
    return FluidConfig(dim=dim, spacing=spec.inner_width / across, wall_model=REAL)


def inside_real_wall(spec: VesselSpec, p: np.ndarray, dim: int) -> np.ndarray:
    """(n,) bool: the vessel-frame points in the closed wall solid of a box or cylinder (1e-12 m spared)."""
    b, t, h, eps = 0.5 * spec.inner_width, spec.wall_thickness, spec.inner_height, 1e-12
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    if dim == 3 and not spec.is_box:
        r = np.hypot(x, y)
        return (r <= b + t + eps) & (z >= -t - eps) & (z <= h + eps) & ((r >= b - eps) | (z <= eps))
    d = 0.5 * spec.section_depth
    out_y = np.abs(y) >= d - eps if dim == 3 else np.zeros(len(p), bool)
    in_outer = (np.abs(x) <= b + t + eps) & (z >= -t - eps) & (z <= h + eps)
    if dim == 3:
        in_outer &= np.abs(y) <= d + t + eps
    return in_outer & ((np.abs(x) >= b - eps) | out_y | (z <= eps))


@pytest.mark.parametrize("spec, dim", [(POURER, 2), (POURER, 3), (CUP, 3)], ids=["box-2d", "box-3d", "cylinder-3d"])
@pytest.mark.parametrize("across", [20, 32])
def test_no_wall_particle_lies_outside_the_real_wall(spec, dim, across):
    cfg = real(spec, across, dim)
    points, volumes = sample_vessel_walls(spec, cfg)
    assert len(points) > 0
    assert inside_real_wall(spec, points, dim).all()
    assert np.all(volumes > 0.0)
    assert numerical_wall_thickness(spec, cfg) == spec.wall_thickness


@pytest.mark.parametrize("spec, dim, across", [(POURER, 2, 20), (POURER, 2, 32), (CUP, 3, 20)], ids=["box-2d-20", "box-2d-32", "cylinder-3d-20"])
def test_a_thin_wall_holds_one_layer_at_its_depth(spec, dim, across):
    """The kept particles are those of ``kernel_layers`` (the liquid's lattice continued behind every face) that
    lie in the vessel's own wall; a wall holding one layer has it moved along each face's normal to
    ``one_layer_depth`` behind the face (5 mm, the wall's own thickness, where that is deeper), corners too, and
    along the faces it stays on the lattice."""
    cfg = real(spec, across, dim)
    points, _ = sample_vessel_walls(spec, cfg)
    layers = slab_particles(spec, FluidConfig(dim=dim, spacing=cfg.spacing, wall_model="kernel_layers"))[0]
    kept = layers[inside_real_wall(spec, layers, dim)]
    depth = min(one_layer_depth(cfg.kernel, cfg.smoothing_ratio, dim) * cfg.spacing, spec.wall_thickness)
    assert len(points) == len(kept)
    assert inside_real_wall(spec, points, dim).all()
    floor = points[:, 2] < 0.0
    assert np.allclose(points[floor, 2], -depth, atol=1e-12)
    b = 0.5 * spec.inner_width
    radius = np.abs(points[:, 0]) if dim == 2 else np.hypot(points[:, 0], points[:, 1])
    side = radius > b + 1e-12
    assert np.allclose(radius[side], b + depth, atol=1e-9)
    if dim == 2:  # along the faces on the liquid's lattice: the floor's x and the side walls' z as kernel_layers lays them
        assert np.array_equal(np.sort(points[floor & ~side, 0]), np.sort(kept[(kept[:, 2] < 0.0) & (np.abs(kept[:, 0]) < b), 0]))
        assert np.array_equal(np.sort(points[side & ~floor, 2]), np.sort(kept[(kept[:, 2] >= 0.0) & (np.abs(kept[:, 0]) > b), 2]))


@pytest.mark.parametrize("dim, across", [(2, 32), (3, 24), (2, 16), (3, 16)])
def test_one_layer_gives_the_first_row_the_covering_walls_kernel_sum_and_gradient(dim, across):
    """Mid-floor, dx/2 above it (the liquid's first row), the one fitted layer at ``one_layer_depth`` sums to the
    covering walls' share of the summation density within 0.5 % of it and matches its gradient (the normal push)
    within 2 %; at the lattice's own depth dx/2 the gradient was 11-12 % short (docs/walls.md). At 16 across the 5 mm
    wall is thinner than dx/2, and its layer stands at that depth all the same, outside the wall."""
    cfg = real(POURER, across, dim)
    thin, volumes = sample_vessel_walls(POURER, cfg)
    full, full_volumes = sample_vessel_walls(POURER, FluidConfig(dim=dim, spacing=cfg.spacing))
    offset = 0.0 if dim == 2 else 0.5 * cfg.spacing  # a 3-D box's floor lattice is cell-centred in y
    first_row = np.array([[0.5 * cfg.spacing, offset, 0.5 * cfg.spacing]])
    assert _kernel_sums(thin, volumes, first_row, cfg)[0] == pytest.approx(_kernel_sums(full, full_volumes, first_row, cfg)[0], rel=0.005)
    push = _gradient_sums(thin, volumes, first_row, cfg)[0, 2]
    assert push == pytest.approx(_gradient_sums(full, full_volumes, first_row, cfg)[0, 2], rel=0.02)


@pytest.mark.parametrize("dim, across", [(2, 12), (3, 16)])
def test_a_box_wall_thinner_than_half_a_spacing_holds_the_first_layer_at_one_layer_depth(dim, across):
    """dx = 15.9 / 11.9 mm: the 5 mm wall holds no layer of its own at dx/2. It holds the covering walls' first layer
    (every particle of theirs dx/2 behind an inner face), moved to ``one_layer_depth`` dx behind it, outside the
    wall; the liquid sees the wall that deep, and the fit makes up the rest of the support."""
    cfg = real(POURER, across, dim)
    assert not holds_a_layer(POURER, cfg.spacing)
    points, volumes = sample_vessel_walls(POURER, cfg)
    layers = slab_particles(POURER, FluidConfig(dim=dim, spacing=cfg.spacing, wall_model="kernel_layers"))[0]
    b, d = 0.5 * POURER.inner_width, 0.5 * POURER.section_depth
    behind = np.stack([np.abs(layers[:, 0]) - b, np.abs(layers[:, 1]) - d if dim == 3 else np.zeros(len(layers)), -layers[:, 2]], axis=1)
    assert len(points) == np.count_nonzero(behind.max(axis=1) < 0.5 * cfg.spacing + 1e-9)
    depth = one_layer_depth(cfg.kernel, cfg.smoothing_ratio, dim) * cfg.spacing
    assert depth > POURER.wall_thickness
    floor, side = points[:, 2] < 0.0, np.abs(points[:, 0]) > b + 1e-12
    assert np.allclose(points[floor, 2], -depth, atol=1e-12)
    assert np.allclose(np.abs(points[side, 0]), b + depth, atol=1e-12)
    assert numerical_wall_thickness(POURER, cfg) == pytest.approx(depth)
    assert np.all(volumes > 0.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_the_crest_is_the_real_lip(dim):
    cfg = real(POURER, 32, dim)
    points, _ = sample_vessel_walls(POURER, cfg)
    b, t, h = 0.5 * POURER.inner_width, POURER.wall_thickness, POURER.inner_height
    lip_wall = points[(points[:, 0] > b) & (points[:, 2] > 0.0)]
    # the +x wall's top row lies half a row below the rim, its outermost column inside the outer face, both within
    # one spacing of the real lip (the layers of kernel_layers reach 3 dx = 17.9 mm out at this resolution)
    assert lip_wall[:, 2].max() == pytest.approx(h - 0.5 * (h / round(h / cfg.spacing)), abs=1e-12)
    assert b + t - cfg.spacing < lip_wall[:, 0].max() <= b + t
    layers = FluidConfig(dim=dim, spacing=cfg.spacing, wall_model=WallModel.KERNEL_LAYERS)
    assert numerical_wall_thickness(POURER, layers) == pytest.approx(3 * cfg.spacing)
    assert sample_vessel_walls(POURER, layers)[0][:, 0].max() > b + 2 * cfg.spacing


def _kernel_sums(points: np.ndarray, volumes: np.ndarray, probes: np.ndarray, cfg: FluidConfig) -> np.ndarray:
    """sum_b V_b W at each probe over the wall particles (points, volumes): their share of the summation density."""
    r = np.linalg.norm(probes[:, None, :] - points[None, :, :], axis=2)
    return (volumes[None, :] * kernel_values(cfg.kernel, r, cfg.smoothing_length, cfg.dim)).sum(axis=1)


@pytest.mark.parametrize("spec, dim, across", [(POURER, 2, 20), (POURER, 2, 32), (CUP, 3, 12)], ids=["box-2d-20", "box-2d-32", "cylinder-3d-12"])
def test_a_thin_walls_volumes_make_up_the_missing_kernel_sum(spec, dim, across):
    """The fitted thin walls sum, at the liquid's first row (the lattice points where walls covering the support
    give more than a tenth of the summation density: the fit's target), to within 0.3 % of rho0 of what those walls
    give, corners included; one row further they fall short by less than 1 % (the price of matching the first row's
    gradient too, test_one_layer_gives_the_first_row_...) and exceed it nowhere by more than 0.3 % (seeded
    compression). Their own slab volumes: 3.8-8 % short."""
    cfg = real(spec, across, dim)
    thin, volumes = sample_vessel_walls(spec, cfg)
    full, full_volumes = sample_vessel_walls(spec, FluidConfig(dim=dim, spacing=cfg.spacing))
    probes = fill_vessel(spec, spec.inner_height, cfg).positions
    probes = probes[(np.hypot(probes[:, 0], probes[:, 1]) > 0.5 * spec.inner_width - cfg.support_radius) | (probes[:, 2] < cfg.support_radius)]
    reference = _kernel_sums(full, full_volumes, probes, cfg)
    near = reference > 0.0
    error = _kernel_sums(thin, volumes, probes[near], cfg) - reference[near]
    first_row = reference[near] > 0.1
    slab = _kernel_sums(thin, slab_particles(spec, cfg)[1], probes[near], cfg)
    assert first_row.sum() > 20
    assert np.abs(error[first_row]).max() < 0.003
    assert error.max() < 0.003
    assert error.min() > -0.01
    assert np.abs(slab - reference[near]).max() > 0.03
    assert np.all(volumes > 0.0)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("slack", [0.3, 0.8])
def test_a_thin_walls_fit_does_not_depend_on_the_spacings_across(dim, slack):
    """The fit's probes are the liquid's first row as it settles against each face, dx/2 from it
    (``first_row_lattice``), wherever the centred fill leaves its first column: a box 20 + slack spacings across (and
    10 + slack deep in 3-D) fits its side walls as the box of whole spacings does. The centred fill's first column
    stands (1 + slack) dx / 2 from each wall: past a slack of 0.75 none of it is within the fit's reach of the one
    layer, which would keep its slab volume, a quarter short."""
    dx = POURER.inner_width / 20
    cfg = FluidConfig(dim=dim, spacing=dx, wall_model=REAL)
    whole = replace(POURER, inner_width=20 * dx, inner_depth=10 * dx)
    offset = replace(POURER, inner_width=(20 + slack) * dx, inner_depth=(10 + slack) * dx)
    lattice = first_row_lattice(offset, cfg)
    assert 0.5 * offset.inner_width - np.abs(lattice[:, 0]).max() == pytest.approx(0.5 * dx, rel=1e-9)
    if dim == 3:
        assert 0.5 * offset.section_depth - np.abs(lattice[:, 1]).max() == pytest.approx(0.5 * dx, rel=1e-9)
    np.testing.assert_array_equal(first_row_lattice(whole, cfg), fill_vessel(whole, whole.inner_height, cfg).positions)

    def side_wall_fit(spec: VesselSpec) -> float:
        """The median over the side walls' particles of the fitted volume over the particle's slab volume (a wall's
        particles along a face are spaced to fill it, so their slab volumes differ between the boxes)."""
        points, volumes = sample_vessel_walls(spec, cfg)
        side = (np.abs(points[:, 0]) > 0.5 * spec.inner_width) & (points[:, 2] > 0.0)
        return float(np.median(volumes[side] / slab_particles(spec, cfg)[1][side]))

    assert side_wall_fit(offset) == pytest.approx(side_wall_fit(whole), rel=0.005)


def _gradient_sums(points: np.ndarray, volumes: np.ndarray, probes: np.ndarray, cfg: FluidConfig) -> np.ndarray:
    """(n, 3) sum_b V_b grad W(p - x_b) at each probe p over the wall particles (points, volumes)."""
    d = probes[:, None, :] - points[None, :, :]
    r = np.linalg.norm(d, axis=2)
    slope = kernel_derivatives(cfg.kernel, r, cfg.smoothing_length, cfg.dim) / np.where(r > 0.0, r, 1.0)
    return np.einsum("pb,pbk->pk", volumes[None, :] * slope, d)


def test_walls_that_cover_the_support_keep_their_slab_volumes():
    thick = VesselSpec("tank", VesselShape.BOX, 0.191, 0.1, 0.2, 0.02, 1180.0)
    cfg = real(thick, 32, 2)  # 20 mm against 3 dx = 17.9 mm
    points, volumes = sample_vessel_walls(thick, cfg)
    assert volumes.sum() == pytest.approx((0.191 + 0.04) * 0.02 + 2 * 0.2 * 0.02, rel=1e-9)  # the wall's section
    assert inside_real_wall(thick, points, 2).all()


@pytest.mark.parametrize("dim", [2, 3])
def test_a_mesh_vessels_confined_walls_lie_in_its_solid(dim):
    spec = mesh_vessel_spec("pourer", load_vessel_mesh(BEAKER), 1180.0)
    cfg = FluidConfig(dim=dim, spacing=0.08 / 16, wall_model=REAL)  # 5 mm against the 3 mm wall: one layer
    points, volumes = sample_vessel_walls(spec, cfg)
    assert len(points) > 0
    _, _, _, solid = classify(spec, points, 0.02)
    assert solid.all()
    assert np.all(volumes > 0.0)


def test_a_mesh_wall_too_thin_for_one_layer_is_refused():
    spec = mesh_vessel_spec("pourer", load_vessel_mesh(BEAKER), 1180.0)
    cfg = FluidConfig(dim=2, spacing=0.08 / 12, wall_model=REAL)  # 6.7 mm: the 3 mm wall holds no layer at dx / 2
    with pytest.raises(InputError, match="fluid.wall_model: the pourer vessel's wall"):
        sample_vessel_walls(spec, cfg)


def test_unset_the_wall_model_is_the_vessels_own_under_dfsph_and_sided_under_wcsph():
    """DFSPH's default walls are the vessel's own, the same particles and volumes as 'real_thickness' set, a box
    wall thinner than dx / 2 included; WCSPH's are 'sided' (the vessel's own wall thickness seen from outside); a
    mesh vessel's cover the support under either solver; a wall model that is set holds for every vessel."""
    dfsph, wcsph = FluidConfig(dim=2, spacing=0.191 / 32), FluidConfig(dim=2, spacing=0.191 / 32, pressure_solver="wcsph")
    assert dfsph.wall_model is None and wall_model_for(POURER, dfsph) is REAL
    default, confined = sample_vessel_walls(POURER, dfsph), sample_vessel_walls(POURER, real(POURER, 32, 2))
    np.testing.assert_array_equal(default[0], confined[0])
    np.testing.assert_array_equal(default[1], confined[1])
    assert wall_model_for(POURER, wcsph) is WallModel.SIDED
    assert numerical_wall_thickness(POURER, wcsph) == pytest.approx(POURER.wall_thickness)
    coarse = FluidConfig(dim=3, spacing=0.191 / 16)  # dx / 2 = 6.0 mm against the 5 mm wall
    assert not holds_a_layer(POURER, coarse.spacing) and holds_a_layer(POURER, 0.01)
    assert wall_model_for(POURER, coarse) is REAL
    assert wall_model_for(POURER, replace(coarse, pressure_solver=PressureSolver.WCSPH)) is WallModel.SIDED
    assert len(sample_vessel_walls(POURER, coarse)[0]) > 0
    beaker = mesh_vessel_spec("pourer", load_vessel_mesh(BEAKER), 1180.0)
    assert wall_model_for(beaker, FluidConfig(dim=2, spacing=0.08 / 24)) is WallModel.KERNEL_LAYERS
    assert wall_model_for(beaker, FluidConfig(dim=2, spacing=0.08 / 24, pressure_solver="wcsph")) is WallModel.KERNEL_LAYERS
    assert wall_model_for(POURER, FluidConfig(dim=2, spacing=0.191 / 32, wall_model="kernel_layers")) is WallModel.KERNEL_LAYERS
    assert wall_model_for(beaker, FluidConfig(dim=2, spacing=0.08 / 24, wall_model="real_thickness")) is REAL


def test_the_scene_sets_the_wall_model_and_refuses_another():
    assert FluidSettings(wall_model="real_thickness").fluid_config(0.191).wall_model is REAL
    with pytest.raises(InputError, match="fluid.wall_model"):
        FluidSettings(wall_model="thin")
    assert math.isclose(FluidSettings().fluid_config(0.191).support_radius, 3 * 0.191 / 32)


def test_a_thin_wall_keeps_the_edges_of_a_box_not_whole_spacings_deep():
    """3-D, 24 across the pourer (0.1 m deep: 12.57 spacings): the floor's lattice across the depth is not aligned
    with the side walls, and its first point under them lies 4.4 mm past their faces, deeper than dx / 2 (3.98 mm).
    A 2 mm wall keeps those edge particles as the 5 mm wall does: the same particles at the same one-layer depth,
    the same fitted volumes."""
    cfg = FluidConfig(dim=3, spacing=POURER.inner_width / 24)
    thick, thick_volumes = sample_vessel_walls(POURER, cfg)
    thin, thin_volumes = sample_vessel_walls(replace(POURER, wall_thickness=0.002), cfg)
    np.testing.assert_array_equal(thin, thick)
    np.testing.assert_allclose(thin_volumes, thick_volumes, rtol=1e-12)


@pytest.mark.parametrize("across", [16, 20, 27])
def test_no_two_particles_of_a_one_layer_wall_coincide(across):
    """A wall just under 3 dx / 2 holds one layer; across a 3-D box's depth that is not whole spacings the floor's
    lattice can put two of its points behind a side wall within that thickness, and moved to the one layer's depth
    they would coincide (200 to 330 pairs at these resolutions): one is kept."""
    cfg = FluidConfig(dim=3, spacing=POURER.inner_width / across)
    points, _ = sample_vessel_walls(replace(POURER, wall_thickness=1.49 * cfg.spacing), cfg)
    nearest, _ = cKDTree(points).query(points, k=2)
    assert nearest[:, 1].min() > 0.5 * cfg.spacing
