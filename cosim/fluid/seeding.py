"""Initial particle sets: lattices filling a vessel or a box of liquid, with hydrostatic densities.

Particles start on a square (cubic) lattice of spacing dx, at least dx/2 from the side walls and the floor, in
the whole number of layers nearest to the requested depth, with the density of a resting column (inverse Tait equation under the liquid above), so a vessel that starts full starts in
equilibrium instead of exploding.

A 3-D cylindrical cup is seeded in rings instead (:func:`disc_layer`), conforming to its wall as the lattice
conforms to a box's: each layer fills the disc to the inner radius R with one particle per dx^2, and its outer ring
lies half a ring spacing inside the wall, whose first layer of dummy particles lies dx/2 outside it
(:mod:`cosim.fluid.wall_sampling`). A square lattice cut to the disc leaves a stair-stepped gap to the wall and
holds 8-15 % less liquid than pi R^2 times its layers at 32-16 particles across, so the liquid's depth at rest
would depend on how far it spreads into the gap. The rings do not start exactly at rest density: each ring's count is
rounded, so its particles' kernel sums differ from the lattice's by up to about 2 % (the three-particle centre ring
and the rings over the floor most). The pressure solver removes that error in its first substep as a velocity that
the liquid keeps (a lasting agitation), so a run that needs the liquid at rest relaxes it first
(:meth:`cosim.fluid.solver.FluidSolver.relax`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cosim.errors import InputError
from cosim.fluid.config import FluidConfig
from cosim.fluid.mesh_sampling import cavity_bounds, fill_mesh_vessel
from cosim.frames import Pose
from cosim.vessel import VesselSpec


@dataclass(frozen=True)
class ParticleSet:
    """Initial liquid: positions (n, 3) m, velocities (n, 3) m/s, densities (n,) kg/m^3 (world frame)."""

    positions: np.ndarray
    velocities: np.ndarray
    densities: np.ndarray

    def __len__(self) -> int:
        return len(self.positions)

    @staticmethod
    def concatenate(sets: list["ParticleSet"]) -> "ParticleSet":
        return ParticleSet(
            np.concatenate([s.positions for s in sets]),
            np.concatenate([s.velocities for s in sets]),
            np.concatenate([s.densities for s in sets]),
        )


def _centred_axis(lo: float, hi: float, dx: float) -> np.ndarray:
    """Lattice coordinates in [lo, hi], spacing dx, centred, at least dx/2 from both ends."""
    n = int(math.floor((hi - lo) / dx + 1e-9))
    if n < 1:
        return np.zeros(0)
    start = 0.5 * (lo + hi) - 0.5 * (n - 1) * dx
    return start + dx * np.arange(n)


def _layers(height: float, dx: float) -> int:
    """Whole particle layers that represent a liquid ``height`` (m): the nearest count, so the represented height
    n dx is within dx/2 of the requested one (rounding down would lose up to a layer)."""
    return max(1, int(round(height / dx)))


def hydrostatic_density(depth: np.ndarray, cfg: FluidConfig) -> np.ndarray:
    """Density (kg/m^3) at ``depth`` (m) below the free surface of a resting liquid: inverse Tait equation."""
    b = cfg.rest_density * cfg.sound_speed**2 / cfg.gamma
    pressure = cfg.rest_density * cfg.gravity_magnitude * np.maximum(depth, 0.0)
    return cfg.rest_density * (1.0 + pressure / b) ** (1.0 / cfg.gamma)


def liquid_block(lo, hi, cfg: FluidConfig, pose: Pose | None = None) -> ParticleSet:
    """A resting block of liquid filling the local box [lo, hi] (m), placed by ``pose`` (upright assumed for
    the hydrostatic profile). In 2-D only the y = 0 layer is made."""
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    dx = cfg.spacing
    xs = _centred_axis(lo[0], hi[0], dx)
    ys = np.zeros(1) if cfg.dim == 2 else _centred_axis(lo[1], hi[1], dx)
    n_z = _layers(hi[2] - lo[2], dx)
    zs = lo[2] + dx * (0.5 + np.arange(n_z))
    if len(xs) == 0 or len(ys) == 0 or n_z == 0:
        raise InputError(f"liquid block {lo.tolist()}..{hi.tolist()} m holds no particle at spacing {dx:g} m")
    gx, gy, gz = np.meshgrid(xs, ys, zs, indexing="ij")
    local = np.stack([gx.ravel(), gy.ravel(), gz.ravel()], axis=1)
    surface = lo[2] + n_z * dx
    return _place(local, surface - local[:, 2], cfg, pose)


# Least liquid the particles resolve: kernel support 2h = 3 dx at the default h = 1.5 dx, so below these counts every
# particle is within a wall's reach of both sides.
MIN_FILL_LAYERS = 3
MIN_PARTICLES_ACROSS = 4


def fill_layers(spec: VesselSpec, fill_depth: float, dx: float) -> int:
    """Particle layers :func:`fill_vessel` seeds for ``fill_depth`` (m) at spacing ``dx`` (m): never above the rim."""
    return min(_layers(fill_depth, dx), int(math.floor(spec.inner_height / dx + 1e-9)))


def check_resolution(spec: VesselSpec, fill_depth: float, cfg: FluidConfig) -> None:
    """Refuse a liquid the particles cannot resolve (InputError naming the remedy): fewer than MIN_FILL_LAYERS
    layers deep, or fewer than MIN_PARTICLES_ACROSS across the vessel's inner width (and, in 3-D, its depth).

    With the kernel support of 2h = 3 dx, such a liquid has no particle outside the walls' reach; the stability
    matrix (docs/stability.md) showed them creating energy from wall motion without any other symptom.
    """
    dx = cfg.spacing
    layers = fill_layers(spec, fill_depth, dx)
    if layers < MIN_FILL_LAYERS:
        raise InputError(
            f"fill_depth: {fill_depth:.4g} m is {layers} particle layers at spacing {dx:.4g} m; at least "
            f"{MIN_FILL_LAYERS} are needed (a deeper fill, or a spacing <= {fill_depth / MIN_FILL_LAYERS:.4g} m)"
        )
    across = [("inner width", spec.inner_width)] + ([("depth", spec.section_depth)] if cfg.dim == 3 else [])
    for name, size in across:
        n = int(math.floor(size / dx + 1e-9))
        if n < MIN_PARTICLES_ACROSS:
            raise InputError(
                f"spacing: {dx:.4g} m puts {n} particles across the vessel's {name} ({size:.4g} m); at least "
                f"{MIN_PARTICLES_ACROSS} are needed (spacing <= {size / MIN_PARTICLES_ACROSS:.4g} m)"
            )


def fill_vessel(spec: VesselSpec, fill_depth: float, cfg: FluidConfig, pose: Pose | None = None) -> ParticleSet:
    """Liquid filling an upright vessel to ``fill_depth`` (m) on the lattice (a 3-D cylinder's in rings,
    :func:`disc_layer`); the vessel is placed by ``pose``.
    Raises InputError for a liquid the particles cannot resolve (:func:`check_resolution`)."""
    spec.fill_volume(fill_depth)  # range check against the rim
    check_resolution(spec, fill_depth, cfg)
    dx = cfg.spacing
    n_z = fill_layers(spec, fill_depth, dx)
    if spec.is_mesh:
        (lo_x, lo_y, _), (hi_x, hi_y, _) = cavity_bounds(spec)
        local = liquid_block((lo_x, lo_y, 0.0), (hi_x, hi_y, fill_depth), cfg, None).positions
        local = local[fill_mesh_vessel(spec, local, dx, cfg.dim)]
        local = local[local[:, 2] < n_z * dx]
    elif spec.is_box or cfg.dim == 2:
        b = 0.5 * spec.inner_width
        d = 0.5 * spec.section_depth
        local = liquid_block((-b, -d, 0.0), (b, d, fill_depth), cfg, None).positions
        local = local[local[:, 2] < n_z * dx]
    else:
        disc = disc_layer(0.5 * spec.inner_width, dx)
        zs = dx * (0.5 + np.arange(n_z))
        local = np.concatenate([np.column_stack([disc, np.full(len(disc), z)]) for z in zs])
    return _place(local, n_z * dx - local[:, 2], cfg, pose)


def disc_layer(radius: float, dx: float) -> np.ndarray:
    """(n, 2) points (m) filling the disc r <= ``radius`` with one particle per dx^2 of area, for a cylinder's liquid.

    The disc is cut into round(radius / dx) annuli of equal width w; annulus i holds round(2 pi r_i w / dx^2)
    particles evenly spaced on its mid-circle r_i = (i + 1/2) w. So the layer holds pi radius^2 / dx^2 particles to
    within half a particle per annulus (each particle's volume is the lattice's dx^3), and the outermost ring lies
    w/2 inside the wall, as a lattice lies dx/2 inside a box's.
    """
    n_rings = max(1, round(radius / dx))
    width = radius / n_rings
    rings = []
    for i in range(n_rings):
        r = (i + 0.5) * width
        count = max(1, round(2.0 * math.pi * r * width / dx**2))
        angle = 2.0 * math.pi * np.arange(count) / count
        rings.append(np.column_stack([r * np.cos(angle), r * np.sin(angle)]))
    return np.concatenate(rings)


def _place(local: np.ndarray, depth: np.ndarray, cfg: FluidConfig, pose: Pose | None) -> ParticleSet:
    world = local if pose is None else pose.transform(local)
    if cfg.dim == 2:
        world = world.copy()
        world[:, 1] = 0.0
    return ParticleSet(world, np.zeros_like(world), hydrostatic_density(depth, cfg))
