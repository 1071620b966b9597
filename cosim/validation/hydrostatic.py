"""Hydrostatic tank: a resting column must carry p(z) = rho0 g (H - z).

A box tank of inner width ``width`` is filled to ``fill`` and left alone for ``duration``; then the SPH pressure
is interpolated (Shepard, the solver's kernel) at probes more than 2h from walls, floor and surface and compared
with rho0 g (H - z), H being the liquid's actual height (its volume over the tank's floor area: the lattice
holds a whole number of layers). Also: max density error, particles outside the tank, volume drift, and the
liquid's vertical force on the tank against its weight.

``scene``: a scene file whose pourer (a box, a cylinder or a mesh, ``[vessels.pourer]``) is the tank instead, as it
is; H is then the height at which the tank's cavity holds the liquid's volume (a mesh's V(H), or its pour-plane
section's area S(H) times the depth in 2-D; the lattice keeps half a spacing from curved walls, so the settled
liquid is lower than its seeded layers) and the probes lie in the pour plane within the inner width.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from cosim.fluid.config import GRAVITY
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.pour_scene import load_scene
from cosim.validation.common import CaseResult, FluidCaseParams, Metric, case_fluid_config, new_figure, require_particles_across, whole_spacings
from cosim.vessel import VesselSpec
from declared_settings.setting import documented, setting

# Acceptance: pressure within 2 % of rho0 g (H - z) away from walls and surface, density error <= 1 % (the weakly
# compressible bound (v_max / c0)^2 with c0 >= 10 v_max: Monaghan 1994, "Simulating free surface flows with SPH"),
# vertical reaction = liquid weight within 1 %, no leak, volume conserved.
PRESSURE_TOLERANCE = 0.02
DENSITY_ERROR_LIMIT = 0.01
WEIGHT_TOLERANCE = 0.01
MIN_PARTICLES_ACROSS = 40
PROBE_CLEARANCE = 2.0  # probes stay this many smoothing lengths h from walls, floor and surface
INTERVAL = 0.02  # s, how often vessel poses are (re)set; the tank does not move


HYDROSTATIC = "hydrostatic"


@documented
@dataclass(frozen=True)
class Params(FluidCaseParams):
    """A tank of liquid at rest.

    scene: a scene file whose pourer is the tank ('': a box of ``width`` and ``depth``).
    """

    width: float = setting(VesselSpec.inner_width, HYDROSTATIC, "Tank inner width (B).", "m", 0.0, 2.0, lo_open=True)
    fill: float = setting(0.159, HYDROSTATIC, "Fill depth.", "m", 0.0, 2.0, lo_open=True)
    duration: float = setting(2.0, HYDROSTATIC, "Simulated time before measuring.", "s", 0.0, 60.0, lo_open=True)
    scene: str = ""

    def __post_init__(self) -> None:
        super().__post_init__()
        require_particles_across("spacing", self.tank_width, self.resolved_spacing, 8)  # refused before any case runs

    @property
    def resolved_spacing(self) -> float:
        return self.spacing if self.spacing is not None else self.tank_width / MIN_PARTICLES_ACROSS

    @property
    def tank_width(self) -> float:
        return self.scene_tank().inner_width if self.scene else self.width

    def scene_tank(self) -> VesselSpec:
        """The scene's pourer as the tank."""
        return load_scene(self.scene).vessels.pourer.spec("tank", "vessels.pourer")


def _interpolate(points: np.ndarray, x: np.ndarray, values: np.ndarray, volumes: np.ndarray, h: float) -> np.ndarray:
    """Shepard-normalised SPH interpolation with the Wendland C2 shape (normalisation cancels)."""
    out = np.empty(len(points))
    for k, p in enumerate(points):
        q = np.linalg.norm(x - p, axis=1) / h
        w = np.where(q < 2.0, (1.0 - 0.5 * q) ** 4 * (2.0 * q + 1.0), 0.0) * volumes
        out[k] = (w * values).sum() / w.sum()
    return out


def _mesh_liquid_height(tank: VesselSpec, volume: float, dim: int, depth: float) -> float:
    """m: the height H at which the mesh tank holds ``volume`` (m^3): V(H), or in 2-D S(H) ``depth``; by bisection
    to a micrometre (V and S grow monotonically with H)."""
    held = tank.mesh.cavity_volume if dim == 3 else (lambda h: tank.mesh.section_area(h) * depth)
    lo, hi = 0.0, tank.inner_height
    while hi - lo > 1e-6:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if held(mid) < volume else (lo, mid)
    return 0.5 * (lo + hi)


def run(p: Params) -> CaseResult:
    dx = p.resolved_spacing
    if p.scene:
        tank = p.scene_tank()
        width, depth = tank.inner_width, tank.section_depth
    else:
        width, depth = whole_spacings(p.width, dx), p.tank_depth(dx)
        tank = VesselSpec(name="tank", inner_width=width, inner_depth=depth, inner_height=p.fill * 1.25 + 4 * dx)
    margin = 0.05 * width + 10 * dx
    half = 0.5 * width + margin
    cfg = case_fluid_config(
        p.dim, dx, p.fill, depth, (-half, -0.5 * depth - margin, -margin), (half, 0.5 * depth + margin, tank.inner_height + margin), p.solver,
        numerics=p.numerics,
    )
    solver = FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, p.fill, cfg), device=p.device)
    start = time.perf_counter()
    while solver.time < p.duration - 1e-9:
        solver.advance(min(INTERVAL, p.duration - solver.time))
    wall = time.perf_counter() - start

    x, pressure, rho, active = solver.positions(), solver.pressures(), solver.densities(), solver.active_mask()
    h = cfg.smoothing_length
    volume0 = solver.n_particles * cfg.particle_volume
    if p.scene and tank.is_mesh:
        height = _mesh_liquid_height(tank, volume0, p.dim, depth)
    else:
        height = volume0 / (tank.inner_floor_area if p.dim == 3 else width * depth)
    clearance = PROBE_CLEARANCE * h
    zs = np.linspace(clearance, height - clearance, 12)
    xs = np.linspace(-0.5 * width + clearance, 0.5 * width - clearance, 5)
    probes = np.array([(px, 0.0, pz) for px in xs for pz in zs])
    probe_p = _interpolate(probes, x, pressure, cfg.particle_mass / rho, h)
    ref_p = cfg.rest_density * GRAVITY * (height - probes[:, 2])
    rel = (probe_p - ref_p) / ref_p
    worst = int(np.argmax(np.abs(rel)))
    density_error = float(np.abs(rho - cfg.rest_density).max() / cfg.rest_density)
    inside = solver.last_report.last.volume_in_vessel[0]
    leaked = int(solver.n_particles - round(inside / cfg.particle_volume))
    weight = volume0 * cfg.rest_density * GRAVITY
    reaction = -float(solver.vessel_wrenches()[0, 2])
    metrics = [
        Metric("pressure (worst probe)", float(probe_p[worst]), float(ref_p[worst]), float(rel[worst]), PRESSURE_TOLERANCE, "Pa"),
        Metric("max density error", density_error, 0.0, density_error, DENSITY_ERROR_LIMIT, "", absolute=True),
        Metric("vertical reaction", reaction, weight, (reaction - weight) / weight, WEIGHT_TOLERANCE, "N"),
        Metric("particles outside the tank", float(leaked), 0.0, float(leaked), 0.0, "", absolute=True),
        Metric("liquid volume in the tank", inside, volume0, (inside - volume0) / volume0, 0.0, "m^3"),
    ]
    raw = {
        "z": probes[:, 2].tolist(),
        "x": probes[:, 0].tolist(),
        "pressure": probe_p.tolist(),
        "reference_pressure": ref_p.tolist(),
        "liquid_height": height,
        "leaked": leaked,
        "max_density_error": density_error,
        "reaction_force_z": reaction,
        "fluid_weight": weight,
        "particles": solver.n_particles,
        "steps": solver.step_count,
        "active": int(active.sum()),
    }
    params = dict(width=width, fill=p.fill, spacing=dx, dim=p.dim, device=p.device, solver=p.solver.value, duration=p.duration, depth=depth,
                  tank=tank.shape.value, scene=p.scene)
    return CaseResult("hydrostatic", params, metrics, raw, wall)


def plot(result: CaseResult, path) -> None:
    fig, ax, plt = new_figure(f"Hydrostatic tank ({result.parameters['dim']}-D): pressure at the probes")
    z, pr, ref = map(np.asarray, (result.raw["z"], result.raw["pressure"], result.raw["reference_pressure"]))
    order = np.argsort(z)
    ax.plot(ref[order], z[order], "k-", label="rho0 g (H - z)")
    ax.plot(pr, z, "o", ms=4, label="SPH (Shepard interpolation)")
    ax.set_xlabel("pressure (Pa)")
    ax.set_ylabel("z above the tank floor (m)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
