"""Dummy wall particles of a vessel, in the vessel frame (numpy, done once per run).

The walls hold layers of dummy particles (Adami, Hu & Adams 2012), filled one of two ways
(:class:`cosim.fluid.config.WallModel`):

- ``kernel_layers``: ``n_layers = ceil(2h / dx)`` layers of spacing dx cover the whole kernel support behind every
  wetted face. Where the vessel's wall is thinner than that, the layers extend beyond its outer face: the liquid
  sees a wall ``numerical_wall_thickness`` thick (the inner faces, which hold the liquid, are exact; the outer faces
  and the pour lip move outwards by the difference).
- ``real_thickness``: the same lattice, the liquid's own continued behind every wetted face (layers at depths
  dx/2, 3 dx/2, ... as Adami, Hu & Adams 2012 place theirs), kept only where it lies inside the vessel's own wall
  (depth behind the inner faces at most t), so the outer faces and the pour lip are the vessel's: the layers whose
  centres fit in the wall, at least one. A wall thinner than the kernel support then lacks the particles behind it
  that a liquid particle near its face would sum over; their volumes are fitted to make that up
  (:func:`fit_wall_volumes`). A box's or cylinder's wall that holds one layer (t < 3 dx / 2) has it moved deeper, to
  :func:`one_layer_depth` (about 0.6 dx, or t where the wall is thinner), so that the fitted layer also gives the
  liquid's first row the covering walls' kernel gradient; along the faces it stays on the lattice. A box's or
  cylinder's wall thinner than dx/2 holds no layer of its own; it gets the lattice's first layer at
  :func:`one_layer_depth`, the one place where one layer gives the first row both moments of the missing support,
  which is outside the wall by one_layer_depth dx - t (:func:`one_layer_wall_depth`; docs/walls.md, "A wall
  thinner than dx / 2"). A mesh wall keeps the lattice's depth and needs t >= dx/2
  (:mod:`cosim.fluid.mesh_sampling`).

- ``sided`` (WCSPH): both sets, each seen from one side of the vessel (:func:`wall_sides`): the liquid inside the
  vessel's inner volume sees the ``kernel_layers`` particles, the liquid outside it (over the rim, in the stream,
  on the outer faces) the ``real_thickness`` ones, as fixed ghost particles are seen only from the liquid's side of
  a wall (Marrone et al. 2011, "delta-SPH model for simulating violent impact flows", CMAME 200). The liquid at rest
  in the vessel is held as by covering walls; the crest and the outer faces it leaves over are the vessel's own.

Layers sit below the rim, so liquid flowing over the rim sees the wall beneath it. In 2-D only the section in the
pour plane (local y = 0) is filled: the floor and the +x / -x walls; a cylinder's section is that of a box of width
2R. Each particle carries its own volume (m^dim): the slab volume divided by the number of particles in it, close
to dx^dim (fitted where the wall is thinner than the support).
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace

import numpy as np

from cosim.errors import InputError
from cosim.fluid.config import DEFAULT_WALL_MODEL, FluidConfig, KernelType, WallModel
from cosim.fluid.mesh_sampling import mesh_wetted_layer, sample_mesh_walls
from cosim.fluid.neighbors import SEEN_ALWAYS, SEEN_FROM_INSIDE, SEEN_FROM_OUTSIDE
from cosim.fluid.sph_kernels import kernel_derivatives, kernel_values, lattice_kernel_sum
from cosim.vessel import VesselSpec


def wall_layers(spacing: float, support: float) -> int:
    """Number of dummy-particle layers that cover the kernel support."""
    return max(1, math.ceil(support / spacing - 1e-9))


def _flat_wall_sums(depths: tuple[float, ...], smoothing_ratio: float, kernel: KernelType, dim: int) -> tuple[float, float]:
    """(S, dS/dd) of layers of wall particles at ``depths`` behind a flat face (in units of dx; each layer the
    liquid's lattice continued tangentially, volume dx^dim) at a point dx/2 in front of the face, over a lattice
    point's tangential offsets: S = sum_b W (in units of 1/dx^dim), dS/dd its derivative with the point's distance d
    from the face (negative: the sum falls away from the wall)."""
    reach = math.ceil(2.0 * smoothing_ratio)
    axis = np.arange(-reach, reach + 1, dtype=float)
    tangential = np.stack(np.meshgrid(*([axis] * (dim - 1)), indexing="ij"), axis=-1).reshape(-1, dim - 1)
    s2 = (tangential**2).sum(axis=1)
    total, slope = 0.0, 0.0
    for depth in depths:
        normal = 0.5 + depth
        r = np.sqrt(s2 + normal**2)
        total += float(kernel_values(kernel, r, smoothing_ratio, dim).sum())
        slope += float((kernel_derivatives(kernel, r, smoothing_ratio, dim) * normal / r).sum())
    return total, slope


@functools.cache
def one_layer_depth(kernel: KernelType, smoothing_ratio: float, dim: int) -> float:
    """Depth (in units of dx) behind the inner face at which a wall holding one layer of dummy particles places it.

    Walls covering the support (layers at dx/2, 3 dx/2, ...) give the liquid's first row, dx/2 from the face, a
    wall share S_ref of its kernel sum and G_ref of that sum's gradient. One layer at depth delta, its volume V
    fitted so that V S_1(delta) = S_ref (:func:`fit_wall_volumes`), gives the gradient V G_1(delta): at the
    lattice's own depth dx/2 that is 0.88-0.89 G_ref (Wendland C2, h = 1.5 dx), so the first row's summation
    density rises away from the wall, and a solve that holds it to rho0 (DFSPH) or a pressure force on it (WCSPH)
    pushes that row into the wall. Here delta is the depth at which both hold, G_1 / S_1 = G_ref / S_ref (the
    zeroth and first moments of the missing support matched at the first row; the volume then 1.31 dx^2 in 2-D,
    1.27 dx^3 in 3-D): 0.623 dx in 2-D and 0.605 dx in 3-D for that kernel and ratio, found by
    scipy.optimize.brentq between the covering walls' first two layers. The rows behind the first, which the
    covering walls reach with their first layer only, then sum a little short of them (0.4 % of rho0 mid-face)
    instead of over."""
    from scipy.optimize import brentq

    covering = tuple(k + 0.5 for k in range(wall_layers(1.0, 2.0 * smoothing_ratio)))
    total, slope = _flat_wall_sums(covering, smoothing_ratio, kernel, dim)
    mismatch = lambda depth: (lambda s, g: g / s)(*_flat_wall_sums((depth,), smoothing_ratio, kernel, dim)) - slope / total  # noqa: E731
    return float(brentq(mismatch, 0.5, 1.5))


def holds_a_layer(spec: VesselSpec, spacing: float) -> bool:
    """Whether ``spec``'s wall holds a layer of the liquid's lattice continued behind its inner faces: the first
    layer's centres lie dx/2 deep, so the wall must be at least ``spacing`` (m) / 2 thick."""
    return spec.wall_thickness * (1.0 + 1e-9) >= 0.5 * spacing


def one_layer_wall_depth(spec: VesselSpec, cfg: FluidConfig) -> float:
    """Depth (m) behind the inner faces of a box's or cylinder's wall that holds one layer of dummy particles
    under ``real_thickness``: :func:`one_layer_depth` dx, or the wall's own thickness t where that is less and the
    wall holds the lattice's first layer (t >= dx/2, :func:`holds_a_layer`). A thinner wall holds none of its own,
    and its layer stands at :func:`one_layer_depth` dx, outside the wall's outer face."""
    depth = one_layer_depth(cfg.kernel, cfg.smoothing_ratio, cfg.dim) * cfg.spacing
    return min(depth, spec.wall_thickness) if holds_a_layer(spec, cfg.spacing) else depth


def wall_model_for(spec: VesselSpec, cfg: FluidConfig) -> WallModel:
    """How ``spec``'s walls are filled: ``cfg.wall_model`` where set; where unset the pressure solver's own
    (:data:`cosim.fluid.config.DEFAULT_WALL_MODEL`), except that a mesh vessel's wall, whose confined sampling is not
    validated, gets ``kernel_layers``, and so does a mesh vessel's wall under ``sided``, set or not."""
    model = cfg.wall_model
    if model is None:
        model = DEFAULT_WALL_MODEL[cfg.pressure_solver]
        if model is WallModel.REAL_THICKNESS and spec.is_mesh:
            return WallModel.KERNEL_LAYERS
    if model is WallModel.SIDED and spec.is_mesh:
        return WallModel.KERNEL_LAYERS  # no inner volume test for a mesh
    return model


def numerical_wall_thickness(spec: VesselSpec, cfg: FluidConfig) -> float:
    """Wall thickness (m) the liquid sees: the vessel's own, or under ``kernel_layers`` the dummy layers' if those
    are thicker; under ``real_thickness`` and ``sided`` (whose covering layers beyond the wall are seen only from
    inside) the vessel's own, or a box's or cylinder's wall thinner than dx/2 as deep as its one layer stands
    (:func:`one_layer_wall_depth`)."""
    if wall_model_for(spec, cfg) in (WallModel.REAL_THICKNESS, WallModel.SIDED):
        if spec.is_mesh or holds_a_layer(spec, cfg.spacing):
            return spec.wall_thickness
        return one_layer_wall_depth(spec, cfg)
    return max(spec.wall_thickness, wall_layers(cfg.spacing, cfg.support_radius) * cfg.spacing)


# A box's or cylinder's wall that holds one layer (thinner than 3 dx / 2) keeps the covering lattice's points at most
# this many dx (or its own thickness, if more) behind its inner faces: the first layer. Each slab's lattice steps about
# dx along every axis but is aligned with the faces only along its own normal (a floor's lattice across a 3-D box's
# depth that is not whole spacings is not), so its first point behind another face lies anywhere within a step of
# it, not at dx/2, and may lie deeper than a thin wall is thick
FIRST_LAYER_REACH = 1.0
# Sweeps of the multiplicative fit of the thin walls' volumes (fit_wall_volumes); the kernel sums it matches settle to
# within 0.1 % well before
FIT_SWEEPS = 40
# Probe points per block of the pairwise distances (memory: block x wall particles floats)
PROBE_BLOCK = 512
# The fit's probes are the liquid's first row along the walls: the lattice points whose nearest wall particle is
# nearer than this many dx (the first row's is 0.5 dx + the layer's depth, at most 1.12 dx; the second row's 1 dx
# further)
FIRST_ROW_REACH = 1.5


def _near_pairs(probes: np.ndarray, points: np.ndarray, cfg: FluidConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pairs (probe index, point index, distance r (m)) closer than the kernel support: the probes in blocks
    along x, each against the points within its x range widened by the support."""
    support = cfg.support_radius
    order = np.argsort(probes[:, 0], kind="stable")
    point_order = np.argsort(points[:, 0], kind="stable")
    point_x = points[point_order, 0]
    rows, cols, distances = [], [], []
    for start in range(0, len(probes), PROBE_BLOCK):
        index = order[start:start + PROBE_BLOCK]
        block = probes[index]
        lo, hi = np.searchsorted(point_x, [block[:, 0].min() - support, block[:, 0].max() + support])
        near = point_order[lo:hi]
        r = np.linalg.norm(block[:, None, :] - points[near][None, :, :], axis=2)
        i, j = np.nonzero(r < support)
        rows.append(index[i])
        cols.append(near[j])
        distances.append(r[i, j])
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(distances)


def _kernel_pairs(probes: np.ndarray, points: np.ndarray, cfg: FluidConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pairs (probe index, point index, W (1/m^dim)) closer than the kernel support (:func:`_near_pairs`)."""
    rows, cols, r = _near_pairs(probes, points, cfg)
    return rows, cols, kernel_values(cfg.kernel, r, cfg.smoothing_length, cfg.dim)


def _kernel_sums(pairs, volumes: np.ndarray, n_probes: int) -> np.ndarray:
    """(n_probes,) sum_b V_b W(p - x_b): the walls' share of each probe's summation density, in units of rho0."""
    rows, cols, weights = pairs
    return np.bincount(rows, weights * volumes[cols], n_probes)


def first_row_lattice(spec: VesselSpec, cfg: FluidConfig) -> np.ndarray:
    """(n, 3) m, vessel frame: the lattice of liquid filling ``spec`` to its rim (:func:`cosim.fluid.seeding.fill_vessel`)
    with each half of it against the walls it is nearest to, so that the first row stands dx/2 from every face as
    liquid settles against it. The fill centres its lattice between the walls: across an inner size W that is not
    whole spacings, n = floor(W / dx) columns leave a slack s = W - n dx, and the first column stands (dx + s) / 2
    from each wall, up to a spacing. Here each half moves s / 2 toward its wall (the half on the -x side by -s / 2,
    the other by +s / 2; across the depth likewise for a 3-D box; a 3-D cylinder's rings already lie half a ring's
    width inside its wall, and the floor's first layer stands dx/2 above it). On whole spacings nothing moves."""
    from cosim.fluid.seeding import fill_vessel

    lattice = fill_vessel(spec, spec.inner_height, cfg).positions.copy()
    dx = cfg.spacing
    sizes = [(0, spec.inner_width)]  # (axis, inner size): 2-D sections are boxes
    if cfg.dim == 3:
        sizes = [(0, spec.inner_width), (1, spec.section_depth)] if spec.is_box else []
    for axis, size in sizes:
        slack = size - math.floor(size / dx + 1e-9) * dx
        if slack > 1e-9 * dx:
            lattice[:, axis] += 0.5 * slack * np.sign(lattice[:, axis])
    return lattice


def fit_wall_volumes(spec: VesselSpec, cfg: FluidConfig, points: np.ndarray, volumes: np.ndarray) -> np.ndarray:
    """Volumes (m^dim) of a thin wall's dummy particles ``points`` (their own slab volumes ``volumes`` to start from)
    that make up the kernel support missing behind the wall.

    Near a wall the dummy particles supply the share of a liquid particle's summation density that lies behind the
    face, S(p) = sum_b V_b W(p - x_b) (times rho0); DFSPH holds that density to rho0. Walls covering the support
    (``kernel_layers``: the liquid's own lattice continued behind every face) supply it as the liquid's lattice
    would: S_ref(p). A thinner wall's own layers supply less. As Akinci et al. (2012, "Versatile rigid-fluid
    coupling for incompressible SPH") give boundary particles volumes of their own so that a particle at a wall
    sums to its rest density, the volumes are fitted here so that S(p) = S_ref(p) at the probes p, the liquid's
    first row along the walls: the points of the lattice filling the vessel to its rim with its first row dx/2 from
    every face (:func:`first_row_lattice`) whose nearest wall particle is nearer than FIRST_ROW_REACH dx, where
    the walls' share of the sum is largest (a quarter of it mid-face, against a few per cent one row further):
    FIT_SWEEPS multiplicative sweeps V_b <- V_b sum_p W_pb S_ref(p) / S(p) / sum_p W_pb (each particle scaled by
    the mean shortfall of the probes it reaches, weighted by its kernel there; volumes stay positive). Inner edges
    and corners, where the missing support is largest, get the largest volumes. Particles no probe reaches keep
    their slab volumes. With one layer at :func:`one_layer_depth`, which makes the first row's gradient sum match
    as well, the rows behind the first sum short of the covering walls by up to 0.8 % of rho0 and the liquid seeded
    against the walls is compressed by at most 0.07 % (a pour's box at 20-48 across, a 4 mm cylinder wall at 20;
    0.25 % at 12, where the wall is too thin for that depth): under DFSPH a seeded particle keeps its shortfall as
    its rest offset, and the little compression is removed without setting the liquid moving. Nor can one volume
    per particle match the sums of the wall particles themselves, which lack the layers behind them
    (docs/walls.md).
    """
    probes = first_row_lattice(spec, cfg)
    rows, cols, r = _near_pairs(probes, points, cfg)
    nearest = np.full(len(probes), np.inf)
    np.minimum.at(nearest, rows, r)
    first = nearest < FIRST_ROW_REACH * cfg.spacing
    probes = probes[first]
    reference_points, reference_volumes = slab_particles(spec, replace(cfg, wall_model=WallModel.KERNEL_LAYERS))
    reference = _kernel_sums(_kernel_pairs(probes, reference_points, cfg), reference_volumes, len(probes))
    pairs = _kernel_pairs(probes, points, cfg)
    rows, cols, weights = pairs
    reach = np.bincount(cols, weights, len(points))
    fitted = volumes.copy()
    for _ in range(FIT_SWEEPS):
        sums = _kernel_sums(pairs, fitted, len(probes))
        ratio = np.divide(reference, sums, out=np.ones_like(sums), where=sums > 0.0)
        fitted = np.where(reach > 0.0, fitted * np.bincount(cols, weights * ratio[rows], len(points)) / np.where(reach > 0.0, reach, 1.0), fitted)
    return fitted


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


def slab_particles(spec: VesselSpec, cfg: FluidConfig) -> tuple[np.ndarray, np.ndarray]:
    """The walls' dummy particles (n, 3) in the vessel frame and their slab volumes (n,) (m^dim), before any fit
    (:func:`sample_vessel_walls`). Box and cylinder walls are filled as ``kernel_layers`` fills them (at least the
    vessel's own thickness); under ``real_thickness`` only the particles inside the vessel's own wall are kept. A
    box's or cylinder's wall that holds one layer keeps the first point behind every face (at most max(t,
    FIRST_LAYER_REACH dx) deep, thinner walls included), moved to :func:`one_layer_wall_depth`."""
    h = spec.inner_height
    spacing, dim = cfg.spacing, cfg.dim
    confined = wall_model_for(spec, cfg) is WallModel.REAL_THICKNESS
    if spec.is_mesh:
        return sample_mesh_walls(spec, spacing, numerical_wall_thickness(spec, cfg), dim, confined=confined)
    t = numerical_wall_thickness(spec, replace(cfg, wall_model=WallModel.KERNEL_LAYERS))
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
    points, volumes = np.concatenate([p for p, _ in parts]), np.concatenate([v for _, v in parts])
    if confined:
        one_layer = spec.wall_thickness < 1.5 * spacing and not spec.is_mesh
        kept = max(spec.wall_thickness, FIRST_LAYER_REACH * spacing) if one_layer else spec.wall_thickness
        inside = _depths_outside(spec, points, dim).max(axis=1) <= kept * (1.0 + 1e-9)
        points, volumes = points[inside], volumes[inside]
        if one_layer:
            points = _deepen_one_layer(spec, points, one_layer_wall_depth(spec, cfg), dim)
            _, first = np.unique(np.round(points / spacing, 9), axis=0, return_index=True)
            keep = np.sort(first)  # two points of one slab's lattice behind a face moved onto one: keep the first
            points, volumes = points[keep], volumes[keep]
    return points, volumes


def _deepen_one_layer(spec: VesselSpec, points: np.ndarray, depth: float, dim: int) -> np.ndarray:
    """A box's or cylinder's one layer of wall particles (vessel frame) moved from dx/2 behind each inner face it
    lies behind to ``depth`` (m) behind it, along the face's normal (both normals for a particle behind an inner
    edge or corner); along the faces they stay on the liquid's lattice (:func:`one_layer_depth`)."""
    moved = points.copy()
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    moved[:, 2] = np.where(z < 0.0, -depth, z)
    b = 0.5 * spec.inner_width
    if dim == 2 or spec.is_box:
        moved[:, 0] = np.where(np.abs(x) > b, np.sign(x) * (b + depth), x)
        if dim == 3:
            d = 0.5 * spec.section_depth
            moved[:, 1] = np.where(np.abs(y) > d, np.sign(y) * (d + depth), y)
        return moved
    r = np.hypot(x, y)
    scale = np.where(r > b, (b + depth) / np.where(r > 0.0, r, 1.0), 1.0)
    moved[:, 0], moved[:, 1] = x * scale, y * scale
    return moved


def _depths_outside(spec: VesselSpec, points: np.ndarray, dim: int) -> np.ndarray:
    """(n, k) m: how far each vessel-frame point of a box or cylinder lies outside the inner volume along each
    wall's normal (|x| - b, then |y| - d for a 3-D box, or r - R for a cylinder; -z), zero on the inner side. The
    largest is the depth inside a wall solid of any thickness, their norm the distance to the inner volume."""
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    below = np.maximum(-z, 0.0)
    if dim == 2 or spec.is_box:
        out_x = np.maximum(np.abs(x) - 0.5 * spec.inner_width, 0.0)
        out_y = np.maximum(np.abs(y) - 0.5 * spec.section_depth, 0.0) if dim == 3 else np.zeros_like(y)
        return np.stack([out_x, out_y, below], axis=1)
    return np.stack([np.maximum(np.hypot(x, y) - 0.5 * spec.inner_width, 0.0), below], axis=1)


def covers_support(spec: VesselSpec, cfg: FluidConfig) -> bool:
    """Whether the walls the liquid sees are at least the kernel support's layers thick (always under
    ``kernel_layers``)."""
    return numerical_wall_thickness(spec, cfg) >= wall_layers(cfg.spacing, cfg.support_radius) * cfg.spacing - 1e-12


def sample_vessel_walls(spec: VesselSpec, cfg: FluidConfig) -> tuple[np.ndarray, np.ndarray]:
    """Dummy wall particles (n, 3) in the vessel frame and their volumes (n,) (m^dim), for ``cfg``'s spacing,
    kernel support, dimension and wall model; a thin wall's volumes fitted (:func:`fit_wall_volumes`); under
    ``sided`` the ``kernel_layers`` particles, then the ``real_thickness`` ones (:func:`wall_sides`). Raises
    InputError for a mesh wall too thin to hold a layer."""
    if wall_model_for(spec, cfg) is WallModel.SIDED:
        sets = [sample_vessel_walls(spec, replace(cfg, wall_model=model)) for model in SIDED_SETS]
        return np.concatenate([p for p, _ in sets]), np.concatenate([v for _, v in sets])
    points, volumes = slab_particles(spec, cfg)
    if len(points) == 0:
        raise InputError(f"fluid.wall_model: the {spec.name} vessel's wall ({spec.wall_thickness:.4g} m) holds no "
                         f"dummy particle at spacing {cfg.spacing:.4g} m under 'real_thickness' (a wall needs to be "
                         "thicker than dx / 2; or 'kernel_layers')")
    if covers_support(spec, cfg):
        return points, volumes
    return points, fit_wall_volumes(spec, cfg, points, volumes)


# The two sets of a 'sided' wall, in the order sample_vessel_walls concatenates them, and the liquid each is seen by
SIDED_SETS = (WallModel.KERNEL_LAYERS, WallModel.REAL_THICKNESS)
SIDED_SEEN_FROM = (SEEN_FROM_INSIDE, SEEN_FROM_OUTSIDE)


def wall_sides(spec: VesselSpec, cfg: FluidConfig) -> np.ndarray:
    """(n,) int32, for each particle of :func:`sample_vessel_walls`, which liquid sees it
    (:func:`cosim.fluid.neighbors.wall_seen`): under ``sided`` the covering layers only the liquid inside the
    vessel's inner volume (``SEEN_FROM_INSIDE``), the vessel's own wall only the liquid outside it
    (``SEEN_FROM_OUTSIDE``); every particle of the other models all liquid (``SEEN_ALWAYS``)."""
    if wall_model_for(spec, cfg) is not WallModel.SIDED:
        return np.full(len(slab_particles(spec, cfg)[0]), SEEN_ALWAYS, dtype=np.int32)
    counts = [len(slab_particles(spec, replace(cfg, wall_model=model))[0]) for model in SIDED_SETS]
    return np.repeat(np.array(SIDED_SEEN_FROM, dtype=np.int32), counts)


def wall_rest_offsets(spec: VesselSpec, cfg: FluidConfig, points: np.ndarray, volumes: np.ndarray) -> np.ndarray:
    """(n,) kg/m^3: the wall support each dummy particle of a thin wall lacks, against walls that cover the kernel
    support: o_b = max(rho0 (sum_c dx^dim W(x_b - x_c) - sum_b' V_b' W(x_b - x_b')) / s, 0), c over the covering
    walls' particles (``kernel_layers``: the liquid's lattice continued behind every face, of which the thin wall's
    particles ``points``, volumes ``volumes``, are the part inside the vessel's own wall), b' over the thin wall's
    own (self included), s a resting lattice's kernel sum, as the solver divides by. A thin wall's particle misses
    the layers behind it (0.79 rho0 for one layer with liquid at rest, 0.59 at the inner corners); held to rho0 it
    would never be compressed. With the offset it sums, wherever liquid at rest fills its support, to rho0 exactly
    as a covering wall's particle at the same place does (the liquid's lattice and the covering walls together
    tile its support), and where the liquid does not fill it, as at the rim, it is as short as that particle: the
    offset makes up the missing wall, not missing liquid, so liquid flowing over the rim compresses the crest no
    sooner than it compresses a covering wall's. Walls covering the support need no offset (zeros)."""
    if covers_support(spec, cfg):
        return np.zeros(len(points))
    cover_points, cover_volumes = slab_particles(spec, replace(cfg, wall_model=WallModel.KERNEL_LAYERS))
    cover = _kernel_sums(_kernel_pairs(points, cover_points, cfg), cover_volumes, len(points))
    own = _kernel_sums(_kernel_pairs(points, points, cfg), volumes, len(points))
    return np.maximum(cfg.rest_density * (cover - own) / lattice_kernel_sum(cfg.kernel, cfg.smoothing_ratio, cfg.dim), 0.0)


def wetted_layer(spec: VesselSpec, points: np.ndarray, spacing: float, dim: int) -> np.ndarray:
    """(n,) bool: the wall particles ``points`` (vessel frame) of the layer that faces the liquid, those less than
    one ``spacing`` from the vessel's inner volume (the inner corners' diagonal ones included). Only this layer has
    a full kernel support of liquid and wall in a resting, filled vessel (the deeper ones lack the layers beyond
    the last), so only it can be held to rest density (DFSPH's pressure-carrying wall, ``cosim.fluid.dfsph``)."""
    if spec.is_mesh:
        return mesh_wetted_layer(spec, points, spacing)
    return np.linalg.norm(_depths_outside(spec, points, dim), axis=1) < spacing
