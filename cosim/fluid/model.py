"""Model (static, built once) and State (per particle, two buffers swapped at each reorder) of the SPH liquid.

In 2-D each particle stands for a slab of liquid across the pour plane, of a fixed 3-D volume V = dx^2 d0 (d0 =
``depth_2d``, the depth the liquid was seeded for) and mass M = rho0 V. Inside a vessel of another depth d (a
catcher deeper than the pourer) the same volume spreads over d, so its area in the plane is V / d: the particle's
in-plane SPH mass (per unit depth) is m = M / d, and the liquid packs to the height V_total / (d w) by itself.
A particle takes a vessel's depth when it enters it (:func:`cosim.fluid.sph_common.finish_particle`); the
falling stream keeps the depth of the vessel it left (a pourer's stream is as wide as its lip). The 3-D mass M
does not change, so volumes (count x V), wrenches (per-unit-depth force x the particle's depth = M a) and energies
are the same sums as before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import warp as wp

from cosim.errors import InputError
from cosim.fluid.boundary import SHAPE_BOX, SHAPE_CYLINDER, VesselGeometry
from cosim.fluid.mesh_boundary import SHAPE_MESH
from cosim.fluid.mesh_sampling import cavity_bounds, warp_mesh
from cosim.fluid.config import FluidConfig, WallPressure
from cosim.fluid.memory import check_memory
from cosim.fluid.neighbors import CellGrid
from cosim.fluid.params import SPHParams, make_params
from cosim.fluid.wall_sampling import numerical_wall_thickness, sample_vessel_walls, wall_rest_offsets, wall_sides, wetted_layer
from cosim.vessel import VesselSpec


# Vessels a scene with 'sided' walls may hold: each liquid particle's vessels are the bits of one int32
# (cosim.fluid.sph_common.mark_inside_vessels)
MAX_SIDED_VESSELS = 31


@dataclass
class FluidModel:
    """Static data. Arrays live on ``device``; shapes: N fluid particles, Nb wall samples, V vessels.

    params: :class:`SPHParams`.
    vessel_specs: the V vessel specifications (vessel frames as in ``cosim.vessel``).
    vessels: (V,) :class:`VesselGeometry`.
    b_local: (Nb,) vec3, dummy wall particles in their vessel's frame (m).
    b_vessel: (Nb,) int32, index of the vessel each wall particle belongs to.
    b_volume: (Nb,) float, volume of each wall particle (m^dim; its mass is rho0 times this).
    b_wetted: (Nb,) int32, 1 for the wall particles of the layer facing the liquid
    (:func:`cosim.fluid.wall_sampling.wetted_layer`; DFSPH holds them to rest density too).
    b_side: (Nb,) int32, which liquid sees each wall particle (:func:`cosim.fluid.wall_sampling.wall_sides`: all of
    it, or under ``wall_model = "sided"`` only the liquid inside its vessel, or only the liquid outside).
    one_sided_walls: whether some wall particle is seen from one side only (the substeps then mark which vessels
    hold each liquid particle, :func:`cosim.fluid.sph_common.mark_inside_vessels`).
    b_rest_offset: (Nb,) float, kg/m^3, added to a wall particle's summation density where DFSPH holds the layer
    to its rest sum (``FluidConfig.wall_pressure`` 'solved_rest_sum': :func:`cosim.fluid.wall_sampling.wall_rest_offsets`);
    zeros otherwise.
    b_reach: (V,) numpy, largest distance of a vessel's wall particles from its frame origin (m): wall speed bound.
    wall_thickness: (V,) numpy, wall thickness the liquid sees (m), >= the vessel's own.
    grid, b_grid: neighbour grids for liquid and wall particles (identical cell layout).
    densest_smoothing_ratio: h over the spacing of the densest liquid the particles can pack to (2-D: of the
    smallest in-plane mass, :func:`densest_smoothing_ratio`; the configured ratio otherwise).
    meshes: the mesh vessels' ``wp.Mesh`` (their ids are in ``vessels``; held here so that they live as long).
    """

    config: FluidConfig
    device: wp.context.Device
    params: SPHParams
    vessel_specs: tuple[VesselSpec, ...]
    vessels: wp.array
    b_local: wp.array
    b_vessel: wp.array
    b_volume: wp.array
    b_wetted: wp.array
    b_side: wp.array
    one_sided_walls: bool
    b_rest_offset: wp.array
    b_reach: np.ndarray
    wall_thickness: np.ndarray
    grid: CellGrid
    b_grid: CellGrid
    densest_smoothing_ratio: float
    meshes: tuple = ()

    @property
    def n_vessels(self) -> int:
        return len(self.vessel_specs)

    @property
    def n_boundary(self) -> int:
        return self.b_local.shape[0]

    @property
    def n_particles(self) -> int:
        """N: the liquid grid holds every liquid particle."""
        return self.grid.capacity


def caught_liquid_mass(cfg: FluidConfig, spec: VesselSpec) -> float:
    """In-plane SPH mass (kg/m) of a particle inside ``spec`` in 2-D: m = M / d = rho0 dx^2 d0 / d, with d0 =
    ``depth_2d`` and d the vessel's section depth (exactly ``particle_mass`` where d = d0). 0 (a particle keeps its
    mass) in 3-D, where a particle is a 3-D volume, and without ``free_liquid``: the particle that changes its mass
    is re-measured as free liquid until packed (:func:`cosim.fluid.sph_common.finish_particle`), which the
    continuity density alone cannot do."""
    if cfg.dim != 2 or not cfg.free_liquid:
        return 0.0
    if spec.section_depth == cfg.depth_2d:
        return cfg.particle_mass
    return cfg.particle_mass * cfg.depth_2d / spec.section_depth


def densest_smoothing_ratio(cfg: FluidConfig, specs: tuple[VesselSpec, ...]) -> float:
    """h / dx' for the densest lattice the liquid packs to: a resting 2-D liquid of in-plane mass m has the spacing
    dx' = sqrt(m / rho0) = dx sqrt(m / m0), so the smallest mass any vessel gives (:func:`caught_liquid_mass`) sets
    the largest ratio smoothing_ratio sqrt(m0 / m). The configured ratio where no vessel makes the liquid denser."""
    masses = [m for m in (caught_liquid_mass(cfg, s) for s in specs) if 0.0 < m < cfg.particle_mass]
    if not masses:
        return cfg.smoothing_ratio
    return cfg.smoothing_ratio * math.sqrt(cfg.particle_mass / min(masses))


def _geometry(spec: VesselSpec, wall_thickness: float, liquid_mass: float, mesh: wp.Mesh | None) -> VesselGeometry:
    geo = VesselGeometry()
    geo.shape = SHAPE_MESH if spec.is_mesh else SHAPE_BOX if spec.is_box else SHAPE_CYLINDER
    if mesh is not None:
        geo.mesh = mesh.id
        lo, hi = cavity_bounds(spec)
        geo.cavity_lo = wp.vec3(*lo)
        geo.cavity_hi = wp.vec3(*hi)
    geo.half_width = 0.5 * spec.inner_width
    geo.half_depth = 0.5 * spec.section_depth
    geo.height = spec.inner_height
    geo.thickness = wall_thickness
    geo.com = wp.vec3(*spec.com_local)
    geo.liquid_mass = liquid_mass
    return geo


def build_model(cfg: FluidConfig, specs: tuple[VesselSpec, ...], n_particles: int, device, atomic_replicas: int = 1) -> FluidModel:
    """Fill the walls with dummy particles and allocate the static arrays (after checking that the liquid fits in
    the device's memory, :func:`cosim.fluid.memory.check_memory`)."""
    walls = [sample_vessel_walls(s, cfg) for s in specs]
    samples = [w[0] for w in walls]
    b_local = np.concatenate(samples) if samples else np.zeros((0, 3))
    check_memory(cfg, n_particles, len(b_local), wp.get_device(device))
    b_volume = np.concatenate([w[1] for w in walls]) if walls else np.zeros(0)
    b_wetted = np.concatenate([wetted_layer(s, w[0], cfg.spacing, cfg.dim) for s, w in zip(specs, walls)]) if walls else np.zeros(0, bool)
    b_side = np.concatenate([wall_sides(s, cfg) for s in specs]) if specs else np.zeros(0, np.int32)
    if b_side.any() and len(specs) > MAX_SIDED_VESSELS:
        raise InputError(f"fluid.wall_model: 'sided' walls need at most {MAX_SIDED_VESSELS} vessels (a bit each in a "
                         f"particle's mark), got {len(specs)}")
    rest_sum = cfg.wall_pressure is WallPressure.SOLVED_REST_SUM and not b_side.any()  # DFSPH's; 'sided' is WCSPH's
    b_rest_offset = np.concatenate([wall_rest_offsets(s, cfg, *w) if rest_sum else np.zeros(len(w[0])) for s, w in zip(specs, walls)]) if walls else np.zeros(0)
    b_vessel = np.concatenate([np.full(len(s), k, dtype=np.int32) for k, s in enumerate(samples)]) if samples else np.zeros(0, np.int32)
    reach = np.array([np.linalg.norm(s, axis=1).max() for s in samples]) if samples else np.zeros(0)
    thickness = np.array([numerical_wall_thickness(s, cfg) for s in specs])
    densest = densest_smoothing_ratio(cfg, specs)
    meshes = [warp_mesh(s.mesh.vertices, s.mesh.faces, device) if s.is_mesh else None for s in specs]
    make_grid = lambda capacity: CellGrid(cfg.domain_min, cfg.domain_max, cfg.support_radius, cfg.dim, capacity, device, cfg.grid_reset)  # noqa: E731
    return FluidModel(
        config=cfg,
        device=device,
        params=make_params(cfg, len(specs), atomic_replicas, densest),
        vessel_specs=tuple(specs),
        vessels=wp.array([_geometry(s, t, caught_liquid_mass(cfg, s), m) for s, t, m in zip(specs, thickness, meshes)], dtype=VesselGeometry, device=device),
        b_local=wp.array(b_local.astype(np.float32), dtype=wp.vec3, device=device),
        b_vessel=wp.array(b_vessel, dtype=wp.int32, device=device),
        b_volume=wp.array(b_volume.astype(np.float32), dtype=float, device=device),
        b_wetted=wp.array(b_wetted.astype(np.int32), dtype=wp.int32, device=device),
        b_side=wp.array(b_side, dtype=wp.int32, device=device),
        one_sided_walls=bool(b_side.any()),
        b_rest_offset=wp.array(b_rest_offset.astype(np.float32), dtype=float, device=device),
        b_reach=reach,
        wall_thickness=thickness,
        grid=make_grid(n_particles),
        b_grid=make_grid(len(b_local)),
        densest_smoothing_ratio=densest,
        meshes=tuple(m for m in meshes if m is not None),
    )


@dataclass
class FluidState:
    """Per-particle arrays (N,), world frame, in cell order after each reorder.

    x: m; v: m/s; rho: kg/m^3; p: Pa; active: 1 while simulated, 0 once spilled or broken; pid: the particle's
    original index (to return results in the order the particles were given); kappa_density, kappa_divergence:
    DFSPH only, m^2/s^2, the stiffness (p / rho) each of its two solves applied in the last substep (the warm start
    of the next; zero under WCSPH); free: 1 while the particle is free liquid (WCSPH: memoryless summation density,
    no tension, :func:`cosim.fluid.wcsph.update_free_liquid`; DFSPH: no seeded offset), 0 while it is bound (its
    density follows the continuity equation under WCSPH); rest_offset: DFSPH only, kg/m^3, what a bound particle is held to
    beyond its summation density: the carried density's excess where its support is not full (``surface_density``
    'continuity', :func:`cosim.fluid.dfsph.surface_offset`) or the kernel deficiency it was seeded with
    ('seeded_offset', :func:`cosim.fluid.dfsph.bound_or_free_density`).
    """

    x: wp.array
    v: wp.array
    rho: wp.array
    p: wp.array
    active: wp.array
    pid: wp.array
    kappa_density: wp.array
    kappa_divergence: wp.array
    free: wp.array
    rest_offset: wp.array
    mass: wp.array

    @staticmethod
    def allocate(n: int, device) -> "FluidState":
        return FluidState(
            x=wp.zeros(n, dtype=wp.vec3, device=device),
            v=wp.zeros(n, dtype=wp.vec3, device=device),
            rho=wp.zeros(n, dtype=float, device=device),
            p=wp.zeros(n, dtype=float, device=device),
            active=wp.zeros(n, dtype=wp.int32, device=device),
            pid=wp.zeros(n, dtype=wp.int32, device=device),
            kappa_density=wp.zeros(n, dtype=float, device=device),
            kappa_divergence=wp.zeros(n, dtype=float, device=device),
            free=wp.zeros(n, dtype=wp.int32, device=device),
            rest_offset=wp.zeros(n, dtype=float, device=device),
            mass=wp.zeros(n, dtype=float, device=device),
        )
