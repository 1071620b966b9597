"""The walls' dummy particles under each wall model (cosim.fluid.wall_sampling): ``real_thickness`` keeps every wall
particle inside the vessel's own wall, on the liquid's lattice continued into it, puts the crest at the real lip and
fits the volumes of a thin wall to the kernel sums of walls that cover the support; ``kernel_layers`` is
unchanged."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, WallModel
from cosim.fluid.mesh_sampling import classify
from cosim.fluid.sph_kernels import kernel_values
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.wall_sampling import numerical_wall_thickness, sample_vessel_walls, slab_particles
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


@pytest.mark.parametrize("spec, dim", [(POURER, 2), (CUP, 3)], ids=["box-2d", "cylinder-3d"])
def test_a_thin_wall_holds_the_liquids_lattice_continued_into_it(spec, dim):
    """The kept particles are those of ``kernel_layers`` (the liquid's lattice continued behind every face) that
    lie in the vessel's own wall: at 20 across a 5 mm (4 mm) wall holds the first layer, dx/2 behind the face."""
    cfg = real(spec, 20, dim)
    points, _ = sample_vessel_walls(spec, cfg)
    layers = slab_particles(spec, FluidConfig(dim=dim, spacing=cfg.spacing))[0]
    kept = layers[inside_real_wall(spec, layers, dim)]
    assert len(points) == len(kept)
    assert np.array_equal(points, kept)
    if dim == 2:  # one layer: every particle (corners too) dx/2 behind the face it is nearest
        depth = np.maximum(np.abs(points[:, 0]) - 0.5 * spec.inner_width, -points[:, 2])
        assert np.allclose(depth, 0.5 * cfg.spacing, atol=1e-9)


def test_a_box_wall_thinner_than_half_a_spacing_is_refused():
    cfg = real(POURER, 12, 2)  # 15.9 mm: the 5 mm wall holds no layer at dx / 2
    with pytest.raises(InputError, match="fluid.wall_model: the pourer vessel's wall .* thicker than dx / 2"):
        sample_vessel_walls(POURER, cfg)


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
    layers = FluidConfig(dim=dim, spacing=cfg.spacing)
    assert numerical_wall_thickness(POURER, layers) == pytest.approx(3 * cfg.spacing)
    assert sample_vessel_walls(POURER, layers)[0][:, 0].max() > b + 2 * cfg.spacing


def _kernel_sums(points: np.ndarray, volumes: np.ndarray, probes: np.ndarray, cfg: FluidConfig) -> np.ndarray:
    """sum_b V_b W at each probe over the wall particles (points, volumes): their share of the summation density."""
    r = np.linalg.norm(probes[:, None, :] - points[None, :, :], axis=2)
    return (volumes[None, :] * kernel_values(cfg.kernel, r, cfg.smoothing_length, cfg.dim)).sum(axis=1)


@pytest.mark.parametrize("spec, dim, across", [(POURER, 2, 20), (POURER, 2, 32), (CUP, 3, 12)], ids=["box-2d-20", "box-2d-32", "cylinder-3d-12"])
def test_a_thin_walls_volumes_make_up_the_missing_kernel_sum(spec, dim, across):
    """At the liquid's initial lattice points within reach of the walls, the fitted thin walls sum to within 0.5 %
    of rho0 of what walls covering the support give (their own slab volumes: 3.8-8 % short), corners included."""
    cfg = real(spec, across, dim)
    thin, volumes = sample_vessel_walls(spec, cfg)
    full, full_volumes = sample_vessel_walls(spec, FluidConfig(dim=dim, spacing=cfg.spacing))
    probes = fill_vessel(spec, spec.inner_height, cfg).positions
    probes = probes[(np.hypot(probes[:, 0], probes[:, 1]) > 0.5 * spec.inner_width - cfg.support_radius) | (probes[:, 2] < cfg.support_radius)]
    reference = _kernel_sums(full, full_volumes, probes, cfg)
    near = reference > 0.0
    fitted = _kernel_sums(thin, volumes, probes[near], cfg)
    slab = _kernel_sums(thin, slab_particles(spec, cfg)[1], probes[near], cfg)
    assert np.abs(fitted - reference[near]).max() < 0.005
    assert np.abs(slab - reference[near]).max() > 0.03
    assert np.all(volumes > 0.0)


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


def test_the_scene_sets_the_wall_model_and_refuses_another():
    assert FluidSettings(wall_model="real_thickness").fluid_config(0.191).wall_model is REAL
    with pytest.raises(InputError, match="fluid.wall_model"):
        FluidSettings(wall_model="thin")
    assert math.isclose(FluidSettings().fluid_config(0.191).support_radius, 3 * 0.191 / 32)
