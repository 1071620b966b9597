"""The walls' dummy particles under each wall model (cosim.fluid.wall_sampling): ``real_thickness`` keeps every wall
particle inside the vessel's own wall, puts the crest at the real lip and scales the volumes of a thin wall towards
the kernel sum of walls that cover the support; ``kernel_layers`` is unchanged."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, WallModel
from cosim.fluid.mesh_sampling import classify
from cosim.fluid.sph_kernels import kernel_values
from cosim.fluid.wall_sampling import layer_depths, numerical_wall_thickness, sample_vessel_walls, support_compensation
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
@pytest.mark.parametrize("across", [12, 20, 32])
def test_no_wall_particle_lies_outside_the_real_wall(spec, dim, across):
    cfg = real(spec, across, dim)
    points, volumes = sample_vessel_walls(spec, cfg)
    assert len(points) > 0
    assert inside_real_wall(spec, points, dim).all()
    assert np.all(volumes > 0.0)
    assert numerical_wall_thickness(spec, cfg) == spec.wall_thickness


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


def _kernel_sum(points: np.ndarray, volumes: np.ndarray, probe: np.ndarray, cfg: FluidConfig) -> float:
    """sum_b V_b W at ``probe`` over the wall particles (points, volumes): their share of the summation density."""
    r = np.linalg.norm(probe - points, axis=1)
    return float((volumes * kernel_values(cfg.kernel, r, cfg.smoothing_length, cfg.dim)).sum())


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("across", [20, 32, 40])
def test_a_thin_walls_volumes_make_up_the_missing_kernel_sum(dim, across):
    """Over the floor's middle, at the liquid rows (j + 1/2) dx above it that reach the floor, the compensated
    thin floor's kernel sum is nearer the full layers' (least squares) than the thin floor's own volumes give, and
    at the first row within 2 % of it."""
    cfg = real(POURER, across, dim)
    s = support_compensation(POURER, cfg)
    assert s > 1.0
    thin, thin_volumes = sample_vessel_walls(POURER, cfg)
    full, full_volumes = sample_vessel_walls(POURER, FluidConfig(dim=dim, spacing=cfg.spacing))
    dx = cfg.spacing
    probes = [np.array([0.5 * dx, 0.0, (j + 0.5) * dx]) for j in range(3)]
    reference = np.array([_kernel_sum(full, full_volumes, p, cfg) for p in probes])
    compensated = np.array([_kernel_sum(thin, thin_volumes, p, cfg) for p in probes])
    uncompensated = compensated / s
    assert np.linalg.norm(compensated - reference) < np.linalg.norm(uncompensated - reference)
    assert compensated[0] == pytest.approx(reference[0], rel=0.02)


def test_walls_that_cover_the_support_are_not_compensated():
    thick = VesselSpec("tank", VesselShape.BOX, 0.191, 0.1, 0.2, 0.02, 1180.0)
    cfg = real(thick, 32, 2)  # 20 mm against 3 dx = 17.9 mm
    assert support_compensation(thick, cfg) == 1.0
    depths, widths = layer_depths(thick, cfg)
    assert len(depths) == 3 and widths.sum() == pytest.approx(0.02)
    assert support_compensation(POURER, FluidConfig(dim=2, spacing=cfg.spacing)) == 1.0  # kernel_layers


@pytest.mark.parametrize("dim", [2, 3])
def test_a_mesh_vessels_confined_walls_lie_in_its_solid(dim):
    spec = mesh_vessel_spec("pourer", load_vessel_mesh(BEAKER), 1180.0)
    cfg = FluidConfig(dim=dim, spacing=0.08 / 16, wall_model=REAL)  # 5 mm against the 3 mm wall: one layer
    points, volumes = sample_vessel_walls(spec, cfg)
    assert len(points) > 0
    _, _, _, solid = classify(spec, points, 0.02)
    assert solid.all()
    assert volumes == pytest.approx(support_compensation(spec, cfg) * cfg.spacing**dim)


def test_a_mesh_wall_too_thin_for_one_layer_is_refused():
    spec = mesh_vessel_spec("pourer", load_vessel_mesh(BEAKER), 1180.0)
    cfg = FluidConfig(dim=2, spacing=0.08 / 12, wall_model=REAL)  # 6.7 mm: the 3 mm wall holds no layer at dx / 2
    with pytest.raises(InputError, match="fluid.wall_model"):
        sample_vessel_walls(spec, cfg)


def test_the_scene_sets_the_wall_model_and_refuses_another():
    assert FluidSettings(wall_model="real_thickness").fluid_config(0.191).wall_model is REAL
    with pytest.raises(InputError, match="fluid.wall_model"):
        FluidSettings(wall_model="thin")
    assert math.isclose(FluidSettings().fluid_config(0.191).support_radius, 3 * 0.191 / 32)
