"""Dummy wall particles of a vessel, in the vessel frame (numpy, done once per run).

The walls are filled with layers of particles that cover the whole kernel support behind every wetted face
(Adami, Hu & Adams 2012): ``n_layers = ceil(2h / dx)`` layers of spacing dx. Where the vessel's wall is thinner
than that, the layers extend beyond its outer face: the liquid sees a wall ``numerical_wall_thickness`` thick
(the inner faces, which hold the liquid, are exact; the outer faces and the pour lip move outwards by the
difference, which :func:`numerical_wall_thickness` reports so that lip positions can be corrected). Layers sit
below the rim, so liquid flowing over the rim sees the wall beneath it.

In 2-D only the section in the pour plane (local y = 0) is filled: the floor and the +x / -x walls; a cylinder's
section is that of a box of width 2R. Each particle carries its own volume (m^dim): the slab volume divided by
the number of particles in it, close to dx^dim.
"""

from __future__ import annotations

import math

import numpy as np

from cosim.fluid.mesh_sampling import mesh_wetted_layer, sample_mesh_walls
from cosim.vessel import VesselSpec


def wall_layers(spacing: float, support: float) -> int:
    """Number of dummy-particle layers that cover the kernel support."""
    return max(1, math.ceil(support / spacing - 1e-9))


def numerical_wall_thickness(spec: VesselSpec, spacing: float, support: float) -> float:
    """Wall thickness (m) the liquid sees: the vessel's own, or the dummy layers' if those are thicker."""
    return max(spec.wall_thickness, wall_layers(spacing, support) * spacing)


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


def sample_vessel_walls(spec: VesselSpec, spacing: float, support: float, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Dummy wall particles (n, 3) in the vessel frame and their volumes (n,) (m^dim)."""
    h = spec.inner_height
    t = numerical_wall_thickness(spec, spacing, support)
    if spec.is_mesh:
        return sample_mesh_walls(spec, spacing, t, dim)
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
    return np.concatenate([p for p, _ in parts]), np.concatenate([v for _, v in parts])


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
