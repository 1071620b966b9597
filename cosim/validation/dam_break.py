"""Dam break: surge front of a collapsing liquid column against Martin & Moyce (1952).

A column a wide and ``fill`` high (by default 2 a, the height of the experiment's series the reference data hold:
Martin & Moyce's n^2 = height / width = 2) stands against the closed -x wall of a long tank.
At t = 0 it is released: instantaneously (the barrier vanishes), or, with ``gate_speed``, by a gate lifted off it
at that speed (:mod:`cosim.validation.dam_gate`), as experiments release their columns. The front is the furthest
liquid from the closed wall that is still connected to the bulk (a contiguous run of occupied 2dx bins from the
wall along x, plus dx/2 for the particle's own extent); the height of that leading particle above the floor is kept
with it (``tip_height``), to show that the front compared is the surge's tip on the floor, which is what the
experiment measured. It is compared as Z = front / a against T = t sqrt(2 g / a) with the digitised experiment
(data/martin_moyce_1952_surge_front.csv), at every reference point the run reaches and with no time shift: each
point's Z error, and its time lead, the experiment's T less the T at which the simulated front first reached the
same Z. The time lead tells a release delay (a lead by a fixed time) from a front that runs at another speed (a
lead that changes as the front runs on). The default run reaches every reference point (the last at T = 9.24);
the acceptance counts those with T <= 3.
"""

from __future__ import annotations

import csv
import dataclasses
import math
import time
from dataclasses import dataclass
from importlib import resources

import numpy as np

from cosim.fluid.config import GRAVITY, WallModel
from cosim.fluid.seeding import liquid_block
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.fluid.wall_sampling import numerical_wall_thickness
from cosim.validation.common import CaseResult, FluidCaseParams, Metric, case_fluid_config, new_figure, require_particles_across, whole_spacings
from cosim.validation.dam_gate import MAX_GATE_SPEED, lauber_hager_speed, lifted_gate
from cosim.vessel import VesselSpec
from declared_settings.setting import documented, setting

# Acceptance: surge front within 10 % of Martin & Moyce at every point with T <= 3.
FRONT_TOLERANCE = 0.10
ACCEPTANCE_T_MAX = 3.0
MARTIN_MOYCE_COLUMN = 0.05715  # m, the experiment's a = 2.25 in
# The reference series' column height over its width (Martin & Moyce's n^2). Its late front runs at dZ/dT = 1.68
# (T 4.4 to 9.2), 1.78 m/s: more than a square column's inviscid bound, Ritter's 2 sqrt(g a) = 1.50 m/s (Stoker 1957,
# "Water waves", the dry-bed dam break), which a front on a real floor stays below; 0.84 of a 2 a column's 2.12 m/s
MARTIN_MOYCE_HEIGHT_RATIO = 2.0
PARTICLES_ACROSS = 50  # default resolution across the column
TANK_MARGIN = 3.0  # columns of tank beyond the experiment's front at the last T simulated, for a front that leads it
SAMPLE_INTERVAL = 0.002  # s


def martin_moyce() -> tuple[np.ndarray, np.ndarray]:
    """(T, Z) of the digitised experiment."""
    text = resources.files("cosim.validation").joinpath("data/martin_moyce_1952_surge_front.csv").read_text()
    rows = [r for r in csv.reader(line for line in text.splitlines() if not line.startswith("#"))][1:]
    data = np.array(rows, dtype=float)
    return data[:, 0], data[:, 1]


def surge_front(x: np.ndarray, wall: float, dx: float) -> tuple[float, float]:
    """The surge's front: the distance (m) from the wall at ``wall`` to the end of the liquid connected to it along
    +x (``x``: (n, 3) m), and the height (m) of the leading particle's centre above the floor (z = 0), which tells
    whether the front is the tip on the floor."""
    bins = np.floor((x[:, 0] - wall) / (2.0 * dx)).astype(int)
    occupied = np.zeros(max(bins.max(), 0) + 2, dtype=bool)
    occupied[bins[bins >= 0]] = True
    last = int(np.argmin(occupied)) - 1  # the bin before the first empty one
    in_run = np.flatnonzero((bins >= 0) & (bins <= last))
    lead = in_run[np.argmax(x[in_run, 0])]
    return float(x[lead, 0] - wall + 0.5 * dx), float(x[lead, 2])


def first_reach(T: np.ndarray, Z: np.ndarray, z: float) -> float:
    """The first T at which the series Z(T) reaches ``z`` (linear between samples; NaN if it never does)."""
    above = np.flatnonzero(Z >= z)
    if len(above) == 0:
        return float("nan")
    k = int(above[0])
    if k == 0:
        return float(T[0])
    return float(T[k - 1] + (z - Z[k - 1]) * (T[k] - T[k - 1]) / (Z[k] - Z[k - 1]))


DAM_BREAK = "dam break"


@documented
@dataclass(frozen=True)
class Params(FluidCaseParams):
    """A column of liquid released on a dry floor (Martin & Moyce 1952)."""

    width: float = setting(MARTIN_MOYCE_COLUMN, DAM_BREAK, "Column width a.", "m", 0.0, 2.0, lo_open=True)
    fill: float | None = setting(None, DAM_BREAK, "Column height.", "m", 0.0, 2.0, lo_open=True,
                                 none_means="twice the width, as the reference experiment's column")
    t_max: float = setting(9.5, DAM_BREAK, "Largest dimensionless time T simulated (9.5: past the last reference "
                           "point, T = 9.24).", "", 0.0, 10.0, lo_open=True)
    gate_speed: float | None = setting(None, DAM_BREAK, "The column is released by a gate lifted at this speed "
                                       "(cosim.validation.dam_gate).", "m/s", 0.0, MAX_GATE_SPEED, lo_open=True,
                                       none_means="released instantaneously")

    def __post_init__(self) -> None:
        super().__post_init__()
        require_particles_across("spacing", self.width, self.resolved_spacing, 8)  # refused before any case runs

    @property
    def resolved_spacing(self) -> float:
        return self.spacing if self.spacing is not None else self.width / PARTICLES_ACROSS

    def column_height(self, a: float) -> float:
        """m, the column's height for a column ``a`` m wide: ``fill``, or :data:`MARTIN_MOYCE_HEIGHT_RATIO` a."""
        return MARTIN_MOYCE_HEIGHT_RATIO * a if self.fill is None else self.fill


def run(p: Params) -> CaseResult:
    dx = p.resolved_spacing
    a = whole_spacings(p.width, dx)  # the column the lattice fills; T and Z are scaled by it
    height = p.column_height(a)
    depth = p.tank_depth(dx)
    ref_T, ref_Z = martin_moyce()
    length = (float(np.interp(p.t_max, ref_T, ref_Z)) + TANK_MARGIN) * a
    tank = VesselSpec(name="tank", inner_width=length, inner_depth=depth, inner_height=2.0 * height)
    wall = -0.5 * length
    margin = 10 * dx + 0.02
    cfg = case_fluid_config(
        p.dim, dx, height, depth,
        (wall - margin, -0.5 * depth - margin, -margin), (-wall + margin, 0.5 * depth + margin, tank.inner_height + margin),
        p.solver,
        numerics=p.numerics,
    )
    vessels, poses, gate = [tank], [Pose()], None
    if p.gate_speed is not None:
        covering = numerical_wall_thickness(tank, dataclasses.replace(cfg, wall_model=WallModel.KERNEL_LAYERS))
        gate = lifted_gate(wall, a, height, depth, p.dim, covering, p.gate_speed)
        vessels.append(gate.spec)
        poses.append(gate.pose(0.0))
        top = max(tank.inner_height, gate.top) + margin  # the gate's ceiling stays in the domain at full travel
        cfg = dataclasses.replace(cfg, domain_max=(cfg.domain_max[0], cfg.domain_max[1], top))
    column = liquid_block((wall, -0.5 * depth, 0.0), (wall + a, 0.5 * depth, height), cfg)
    # a relaxed start needs the column held: by the gate, not where it is released at once
    solver = FluidSolver(cfg, vessels, poses, column, device=p.device, relax_start=gate is not None)
    scale = math.sqrt(2.0 * GRAVITY / a)
    t_end = p.t_max / scale
    times, fronts, lifts = [0.0], [surge_front(solver.positions(), wall, dx)], [0.0]
    start = time.perf_counter()
    while solver.time < t_end - 1e-12:
        if gate is not None:
            solver.set_vessel_poses([Pose(), gate.pose(solver.time + SAMPLE_INTERVAL)])
        solver.advance(SAMPLE_INTERVAL)
        x = solver.positions()[solver.active_mask()]
        times.append(solver.time)
        fronts.append(surge_front(x, wall, dx))
        if gate is not None:  # where the solver has moved the gate to
            lifts.append(float(solver.vessel_poses()[1].position[2] - gate.start[2]))
    wall_time = time.perf_counter() - start
    t, (front, tip_height) = np.array(times), np.array(fronts).T
    T, Z = t * scale, front / a
    metrics, points = compare_with_martin_moyce(T, Z)
    raw = {
        "a": a,
        "height": height,
        "t": t.tolist(),
        "front": front.tolist(),
        "tip_height": tip_height.tolist(),
        "T": T.tolist(),
        "Z": Z.tolist(),
        "reference_points": points,
        "gate_lift": lifts if gate is not None else None,
        "lauber_hager_speed": lauber_hager_speed(height, GRAVITY),  # the slowest gate that counts as an instantaneous release
        "particles": solver.n_particles,
        "steps": solver.step_count,
    }
    params = dict(width=a, fill=height, spacing=dx, dim=p.dim, device=p.device, solver=p.solver.value, t_max=p.t_max, depth=depth,
                  gate_speed=p.gate_speed)
    return CaseResult("dam-break", params, metrics, raw, wall_time)


def compare_with_martin_moyce(T: np.ndarray, Z: np.ndarray) -> tuple[list[Metric], list[dict]]:
    """The simulated front Z(T) against every Martin & Moyce point the series reaches, read at the experiment's own T
    (no time shift): one metric per point (within :data:`FRONT_TOLERANCE` where T <= :data:`ACCEPTANCE_T_MAX`) and
    each point's T, Z_reference, Z, relative error and time lead (the experiment's T less the T at which the
    simulated front first reached the same Z)."""
    ref_T, ref_Z = martin_moyce()
    metrics, points = [], []
    for tr, zr in zip(ref_T, ref_Z):
        if tr > T[-1]:
            break
        zs = float(np.interp(tr, T, Z))
        err = (zs - zr) / zr
        lead = tr - first_reach(T, Z, zr)
        points.append({"T": float(tr), "Z_reference": float(zr), "Z": zs, "error": err, "time_lead": lead})
        tol = FRONT_TOLERANCE if tr <= ACCEPTANCE_T_MAX else float("inf")
        metrics.append(Metric(f"front Z at T={tr:.3f}", zs, float(zr), err, tol, ""))
    return metrics, points


def plot(result: CaseResult, path) -> None:
    fig, ax, plt = new_figure(f"Dam break ({result.parameters['dim']}-D, a = {result.raw['a']:.4f} m): surge front")
    speed = result.parameters["gate_speed"]
    release = f"gate lifted at {speed:g} m/s" if speed is not None else "instantaneous release"
    ax.plot(result.raw["T"], result.raw["Z"], "-", label=f"SPH, {release}")
    ref_T, ref_Z = martin_moyce()
    ax.plot(ref_T, ref_Z, "ks", ms=5, label="Martin & Moyce (1952)")
    ax.fill_between(ref_T, ref_Z * (1 - FRONT_TOLERANCE), ref_Z * (1 + FRONT_TOLERANCE), color="0.85", label="+-10 %")
    ax.axvline(ACCEPTANCE_T_MAX, color="0.5", ls=":", lw=1)
    ax.set_xlim(0, max(result.raw["T"][-1], 1.0) * 1.05)
    ax.set_ylim(0.8, max(max(result.raw["Z"]), float(ref_Z[ref_T <= result.raw["T"][-1]].max(initial=2.0))) * 1.1)
    ax.set_xlabel("T = t sqrt(2 g / a)")
    ax.set_ylabel("Z = front / a")
    ax.legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
