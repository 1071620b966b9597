"""Dummy wall particles of a vessel, in the vessel frame (numpy, done once per run).

The walls hold layers of dummy particles (Adami, Hu & Adams 2012), filled one of two ways
(:class:`cosim.fluid.config.WallModel`):

- ``kernel_layers``: ``n_layers = ceil(2h / dx)`` layers of spacing dx cover the whole kernel support behind every
  wetted face. Where the vessel's wall is thinner than that, the layers extend beyond its outer face: the liquid
  sees a wall ``numerical_wall_thickness`` thick (the inner faces, which hold the liquid, are exact; the outer faces
  and the pour lip move outwards by the difference).
- ``real_thickness``: the layers fill the vessel's own wall and nothing beyond it, round(t / dx) of them (at least
  one) across a wall t thick, so the outer faces and the pour lip are the vessel's. A wall thinner than the kernel
  support then lacks the particles behind it that a liquid particle near its face would sum over; their volumes
  make that up (:func:`support_compensation`).

Layers sit below the rim, so liquid flowing over the rim sees the wall beneath it. In 2-D only the section in the
pour plane (local y = 0) is filled: the floor and the +x / -x walls; a cylinder's section is that of a box of width
2R. Each particle carries its own volume (m^dim): the slab volume divided by the number of particles in it, close
to dx^dim, times the compensation.
"""

from __future__ import annotations

import math

import numpy as np

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, WallModel
from cosim.fluid.mesh_sampling import mesh_wetted_layer, sample_mesh_walls
from cosim.fluid.sph_kernels import kernel_values
from cosim.vessel import VesselSpec


def wall_layers(spacing: float, support: float) -> int:
    """Number of dummy-particle layers that cover the kernel support."""
    return max(1, math.ceil(support / spacing - 1e-9))


def numerical_wall_thickness(spec: VesselSpec, cfg: FluidConfig) -> float:
    """Wall thickness (m) the liquid sees: the vessel's own, or under ``kernel_layers`` the dummy layers' if those
    are thicker."""
    if cfg.wall_model is WallModel.REAL_THICKNESS:
        return spec.wall_thickness
    return max(spec.wall_thickness, wall_layers(cfg.spacing, cfg.support_radius) * cfg.spacing)


def layer_depths(spec: VesselSpec, cfg: FluidConfig) -> tuple[np.ndarray, np.ndarray]:
    """Depths (m) behind the wetted face of the walls' dummy layers, and the thickness (m) of wall each stands for.

    A box's or cylinder's wall t thick (:func:`numerical_wall_thickness`) holds round(t / dx) layers (at least one)
    of equal thickness; a mesh's holds the lattice layers (k + 1/2) dx that lie within it (module
    :mod:`cosim.fluid.mesh_sampling`). Raises InputError for a mesh wall too thin to hold one.
    """
    t, dx = numerical_wall_thickness(spec, cfg), cfg.spacing
    if spec.is_mesh:
        depths = dx * (0.5 + np.arange(math.ceil(t / dx + 1e-9)))
        depths = depths[depths < t]
        if len(depths) == 0:
            raise InputError(f"fluid.wall_model: the mesh vessel's wall ({t:.4g} m) holds no dummy layer at spacing "
                             f"{dx:.4g} m under 'real_thickness' (needs a wall thicker than dx / 2, or 'kernel_layers')")
        return depths, np.full(len(depths), dx)
    n = max(1, round(t / dx))
    return (0.5 + np.arange(n)) * (t / n), np.full(n, t / n)


def _face_kernel_sum(depths: np.ndarray, widths: np.ndarray, distance: float, cfg: FluidConfig) -> float:
    """sum_b V_b W (1/m^0, dimensionless) at a point ``distance`` (m) in front of a flat wall whose layers lie at
    ``depths`` behind its face, each standing for ``widths`` of wall, sampled at spacing dx along the face: the wall's
    share of a particle's summation density, in units of rho0."""
    dx, support = cfg.spacing, cfg.support_radius
    reach = math.ceil(support / dx)
    axis = dx * np.arange(-reach, reach + 1)
    along = np.stack(np.meshgrid(*([axis] * (cfg.dim - 1)), indexing="ij"), axis=-1).reshape(-1, cfg.dim - 1)
    lateral2 = (along**2).sum(axis=1)
    total = 0.0
    for depth, width in zip(depths, widths):
        r = np.sqrt(lateral2 + (distance + depth) ** 2)
        total += width * dx ** (cfg.dim - 1) * float(kernel_values(cfg.kernel, r, cfg.smoothing_length, cfg.dim).sum())
    return total


def support_compensation(spec: VesselSpec, cfg: FluidConfig) -> float:
    """Factor (dimensionless, >= 1 for a thin wall) on the volumes of a vessel's dummy particles that makes up the
    kernel support missing behind a wall thinner than it.

    Near a wall the dummy particles supply the share of a liquid particle's summation density that lies behind the
    face, sum_b rho0 V_b W_ib; DFSPH holds that density to rho0. Layers covering the support, at depths (k + 1/2) dx
    with volume dx^dim, supply it as the liquid's own lattice would: S_full(d) (:func:`_face_kernel_sum`) at a liquid
    particle d from the face. The layers of a thinner wall supply S(d) < S_full(d). As Akinci et al. (2012,
    "Versatile rigid-fluid coupling for incompressible SPH") give a single layer of boundary particles larger volumes
    so that a particle at a wall sums to its rest density, the factor s scales the thin wall's volumes, chosen by
    least squares over the liquid layers in reach of the wall, d_j = (j + 1/2) dx < 2h:
    s = sum_j S(d_j) S_full(d_j) / sum_j S(d_j)^2. One factor cannot match the kernel-gradient sum as well (it is
    short by about a fifth at the first liquid layer against a wall 0.84 dx thick at h = 1.5 dx), nor the sums
    of the wall particles themselves, which lack the layers behind them (docs/walls.md). 1 for walls that cover the
    support, and always under ``kernel_layers``.
    """
    dx, support = cfg.spacing, cfg.support_radius
    full = wall_layers(dx, support)
    if cfg.wall_model is WallModel.KERNEL_LAYERS or numerical_wall_thickness(spec, cfg) >= full * dx:
        return 1.0
    depths, widths = layer_depths(spec, cfg)
    full_depths = dx * (0.5 + np.arange(full))
    probes = dx * (0.5 + np.arange(full))
    thin = np.array([_face_kernel_sum(depths, widths, d, cfg) for d in probes])
    reference = np.array([_face_kernel_sum(full_depths, np.full(full, dx), d, cfg) for d in probes])
    return float(thin @ reference / (thin @ thin))


def _axis(lo: float, hi: float, step: float) -> tuple[np.ndarray, float]:
    n = max(1, round((hi - lo) / step))
    h = (hi - lo) / n
    return lo + h * (0.5 + np.arange(n)), h


def _fill_box(lo, hi, step: float, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Cell-centred lattice in the box [lo, hi] (only y = 0 in 2-D) and each point's volume."""
    xs, hx = _axis(lo[0], hi[0], step)
    zs, hz = _axis(lo[2], hi[2], step)
    if dim == 2:
        gx, gz = np.meshgrid(xs, zs, indexing="ij")
        pts = np.stack([gx.ravel(), np.zeros(gx.size), gz.ravel()], axis=1)
        return pts, np.full(len(pts), hx * hz)
    ys, hy = _axis(lo[1], hi[1], step)
    gx, gy, gz = np.meshgrid(xs, ys, zs, indexing="ij")
    pts = np.stack([gx.ravel(), gy.ravel(), gz.ravel()], axis=1)
    return pts, np.full(len(pts), hx * hy * hz)


def _fill_cylinder_shells(r0: float, r1: float, z0: float, z1: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Particles in the annulus r in [r0, r1], z in [z0, z1] (radial layers, rings of about ``step`` spacing)."""
    radii, hr = _axis(r0, r1, step)
    zs, hz = _axis(z0, z1, step)
    pts, vols = [], []
    for r in radii:
        n = max(6, round(2 * math.pi * r / step))
        a = np.arange(n) * 2 * math.pi / n
        ring_volume = 2 * math.pi * r * hr * hz / n
        for z in zs:
            pts.append(np.stack([r * np.cos(a), r * np.sin(a), np.full(n, z)], axis=1))
            vols.append(np.full(n, ring_volume))
    return np.concatenate(pts), np.concatenate(vols)


def _fill_disc(radius: float, z0: float, z1: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Particles in the disc r <= radius, z in [z0, z1]: a centre column plus rings."""
    zs, hz = _axis(z0, z1, step)
    n_rings = max(1, round(radius / step))
    hr = radius / (n_rings + 0.5)
    pts, vols = [], []
    for z in zs:
        pts.append(np.array([[0.0, 0.0, z]]))
        vols.append(np.array([math.pi * (0.5 * hr) ** 2 * hz]))
    inner, outer = _fill_cylinder_shells(0.5 * hr, radius, z0, z1, hr)
    return np.concatenate(pts + [inner]), np.concatenate(vols + [outer])


def sample_vessel_walls(spec: VesselSpec, cfg: FluidConfig) -> tuple[np.ndarray, np.ndarray]:
    """Dummy wall particles (n, 3) in the vessel frame and their volumes (n,) (m^dim), for ``cfg``'s spacing,
    kernel support, dimension and wall model."""
    h = spec.inner_height
    t = numerical_wall_thickness(spec, cfg)
    spacing, dim = cfg.spacing, cfg.dim
    scale = support_compensation(spec, cfg)
    if spec.is_mesh:
        points, volumes = sample_mesh_walls(spec, spacing, t, dim, confined=cfg.wall_model is WallModel.REAL_THICKNESS)
        return points, scale * volumes
    if dim == 2 or spec.is_box:
        b = 0.5 * spec.inner_width
        d = 0.5 * spec.section_depth
        slabs = [  # floor (with the corners), +x wall, -x wall, then +y, -y walls in 3-D
            ((-b - t, -d - t, -t), (b + t, d + t, 0.0)),
            ((b, -d - t, 0.0), (b + t, d + t, h)),
            ((-b - t, -d - t, 0.0), (-b, d + t, h)),
            ((-b, d, 0.0), (b, d + t, h)),
            ((-b, -d - t, 0.0), (b, -d, h)),
        ]
        parts = [_fill_box(lo, hi, spacing, dim) for lo, hi in (slabs[:3] if dim == 2 else slabs)]
    else:
        r = 0.5 * spec.inner_width
        parts = [_fill_disc(r + t, -t, 0.0, spacing), _fill_cylinder_shells(r, r + t, 0.0, h, spacing)]
    return np.concatenate([p for p, _ in parts]), scale * np.concatenate([v for _, v in parts])


def wetted_layer(spec: VesselSpec, points: np.ndarray, spacing: float, dim: int) -> np.ndarray:
    """(n,) bool: the wall particles ``points`` (vessel frame) of the layer that faces the liquid, those less than
    one ``spacing`` from the vessel's inner volume (the inner corners' diagonal ones included). Only this layer has
    a full kernel support of liquid and wall in a resting, filled vessel (the deeper ones lack the layers beyond
    the last), so only it can be held to rest density (DFSPH's pressure-carrying wall, ``cosim.fluid.dfsph``)."""
    if spec.is_mesh:
        return mesh_wetted_layer(spec, points, spacing)
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    below = np.maximum(-z, 0.0)
    if dim == 2 or spec.is_box:
        out_x = np.maximum(np.abs(x) - 0.5 * spec.inner_width, 0.0)
        out_y = np.maximum(np.abs(y) - 0.5 * spec.section_depth, 0.0) if dim == 3 else np.zeros_like(y)
        distance = np.sqrt(out_x**2 + out_y**2 + below**2)
    else:
        out_r = np.maximum(np.hypot(x, y) - 0.5 * spec.inner_width, 0.0)
        distance = np.hypot(out_r, below)
    return distance < spacing
