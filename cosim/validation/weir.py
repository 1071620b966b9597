"""Outflow over a sharp-crested weir: the SPH discharge coefficient against Rehbock's.

A channel (a box vessel, inner floor at z = 0) ends at its +x wall, the weir, whose crest stands P above the
floor: 2-D in the pour plane, or 3-D between side walls ``depth`` apart (whole spacings; the weir spans the channel's
width, a suppressed weir as in Rehbock's flume). A piston, a second box vessel turned on its side so that its floor
is a vertical plate across the whole liquid depth, pushes the liquid toward the weir at the constant speed U, so
that in steady flow the discharge per unit width is q = U D, D being the depth at the piston. The liquid starts
level at P + H0 (the nominal head H0 over the crest), moving at U with the piston; U is Rehbock's discharge at H0
over that depth, so the head the flow settles at is the liquid's own answer.

Over the last ``window`` s of the run the discharge per unit width q (m^2/s: the slope of the liquid's section area
that has passed the weir's upstream face, a particle's share of it being dx^2 in 2-D and dx^3 / depth in 3-D) and
the head H (m: the liquid's level above the crest in a strip centred 4 H0 upstream of the weir, where the surface is
level, from the liquid's section area in the strip) give the coefficient of the weir law

    q = (2/3) C_d sqrt(2 g) H^(3/2)        (H^(3/2) averaged over the window),

compared with Rehbock's C_d = 0.611 + 0.08 H / P (Rehbock 1929, as given by Henderson, "Open Channel Flow", 1966,
Sec. 6.8), valid for a fully ventilated nappe, which the liquid has: nothing fills the space under it (no air is
modelled). In 3-D plates on the side walls above the crest keep the nappe between walls, as a flume does.

The crest is the top of the weir's dummy-particle layers: flat, ceil(2h/dx) spacings thick (3 dx at the default
h = 1.5 dx; the vessel's own 5 mm under ``wall_model = "real_thickness"``). A crest acts as a sharp one while the
head is well above its thickness (the nappe springs clear of the upstream edge); H / thickness is reported.

The piston is a driver, not a vessel under test: its walls are always those that cover the kernel support
(:func:`piston_thickness`), whatever the wall model, so that the liquid it pushes with its floor's outer face sees
a full wall. A wall thinner than the support is fitted for liquid inside its own vessel
(:func:`cosim.fluid.wall_sampling.fit_wall_volumes`, ``wall_rest_offsets``), not against its outer face.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, replace

import numpy as np

from cosim.errors import InputError
from cosim.fluid.config import GRAVITY, FluidConfig, WallModel
from cosim.fluid.seeding import ParticleSet, liquid_block
from cosim.fluid.solver import FluidSolver
from cosim.fluid.wall_sampling import numerical_wall_thickness
from cosim.frames import Pose
from cosim.validation.common import CaseResult, FluidCaseParams, Metric, case_fluid_config, new_figure
from cosim.validation.launch_point import LIP_TOLERANCE
from cosim.vessel import VesselSpec
from declared_settings.setting import documented, setting

# Acceptance: the discharge coefficient within 5 % of Rehbock's at each head.
COEFFICIENT_TOLERANCE = 0.05
HEADS = (0.04, 0.025)  # m, the nominal heads the validation runs (H / P = 0.5 and 0.31 at P = 0.08 m)
HEAD_SPACINGS = 10  # default resolution: particles across the nominal head
# The fewest particle spacings across the nominal head a run is built with: one row of particles over the crest, which
# the head-floor study (cosim.bench.weir_head_floor) reaches down to; below it no particle row is over the crest.
MIN_HEAD_SPACINGS = 1.0
STATION_HEADS = 4.0  # the head is measured this many nominal heads upstream of the weir
STATION_SPACINGS = 10  # width of the head's strip, particle spacings
PISTON_CLEARANCE_HEADS = 3.0  # the piston stays this many nominal heads behind the strip
SAMPLE_INTERVAL = 0.01  # s
# The nappe over a sharp crest, fully ventilated, the approach velocity negligible (Bazin's measurements, as given by
# Chow 1959, "Open-Channel Hydraulics", and Henderson 1966): its lower surface rises from the crest's upstream edge
# to NAPPE_RISE H above the crest at NAPPE_RISE_AT H downstream of the weir's upstream face and passes the crest's
# level again at NAPPE_RETURN_AT H; its upper surface stands NAPPE_UPPER_AT_WEIR H above the crest at the weir.
NAPPE_RISE, NAPPE_RISE_AT, NAPPE_RETURN_AT, NAPPE_UPPER_AT_WEIR = 0.112, 0.25, 0.67, 0.85
NAPPE_EXTENT_HEADS = 1.0  # the nappe's surfaces are read from the weir's upstream face this many nominal heads on
NAPPE_DEPTH_HEADS = 1.0  # liquid up to this many heads below the crest counts as the nappe's
DOMAIN_MARGIN = 0.05  # m, the domain past the channel's walls (downstream: where the nappe leaves it, counted as passed)
WEIR_FACTOR = (2.0 / 3.0) * math.sqrt(2.0 * GRAVITY)  # m^(1/2)/s: q / (C_d H^(3/2))


def rehbock(head: float, crest_height: float) -> float:
    """Rehbock's discharge coefficient of a sharp-crested weir, head and crest height in m."""
    return 0.611 + 0.08 * head / crest_height


WEIR = "weir"


@documented
@dataclass(frozen=True)
class Params(FluidCaseParams):
    """A 2-D channel whose piston drives the liquid over the sharp-crested weir at its end."""

    head: float = setting(HEADS[0], WEIR, "Nominal head H0 over the crest (sets the piston's speed).", "m", 0.005, 0.2)
    crest_height: float = setting(0.08, WEIR, "Crest height P.", "m", 0.02, 0.5)
    duration: float = setting(1.6, WEIR, "Simulated time.", "s", 0.0, 10.0, lo_open=True)
    window: float = setting(0.8, WEIR, "The final stretch over which q and H are measured (the flow settles before "
                            "it).", "s", 0.05, "duration")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.head / self.resolved_spacing < MIN_HEAD_SPACINGS - 1e-9:
            raise InputError(f"spacing: {self.resolved_spacing:g} m gives {self.head / self.resolved_spacing:.1f} particles across "
                             f"the {self.head:g} m head; needs >= {MIN_HEAD_SPACINGS:g}")
        if self.dim == 3:
            dx = self.resolved_spacing
            narrowest = 2.0 * piston_thickness(case_fluid_config(3, dx, self.crest_height, self.depth, (-1, -1, -1), (1, 1, 1),
                                                                 self.solver, numerics=self.numerics)) + dx
            if self.tank_depth(dx) < narrowest - 1e-9:
                raise InputError(f"depth: the 3-D channel's width must hold its piston's two side walls and a spacing, "
                                 f">= {narrowest:.4g} m at spacing {dx:g} m, got {self.depth:g}")

    @property
    def resolved_spacing(self) -> float:
        return self.spacing if self.spacing is not None else self.head / HEAD_SPACINGS


def piston_speed(head: float, crest_height: float) -> float:
    """m/s: the piston speed that supplies Rehbock's discharge at ``head`` through the depth P + head."""
    return rehbock(head, crest_height) * WEIR_FACTOR * head**1.5 / (crest_height + head)


def piston_thickness(cfg: FluidConfig) -> float:
    """m, the piston's wall thickness: the kernel-covering layers', as ``kernel_layers`` lays them (at least the
    default vessel wall's). A thinner wall (``real_thickness``) is fitted for liquid resting in its own vessel's
    cavity and, under DFSPH's ``solved_rest_sum``, offset for the covering layers it lacks behind its inner face
    (its inner corners the most); the piston pushes with its floor's outer face and slides its trailing wall on the
    channel's floor, so its corner particles would sum the floor's particles on top of that offset and be held
    compressed with no liquid to move, a stiffness that fires the liquid at the plate's foot off. A covering wall
    has neither fit nor offset (docs/walls.md)."""
    return numerical_wall_thickness(VesselSpec(), replace(cfg, wall_model=WallModel.KERNEL_LAYERS))


class Channel:
    """The channel, its piston and where things are measured (world frame, m; the weir's upstream face at x = 0).
    ``wall_thickness``: the channel's walls the liquid sees (the weir plate's); ``piston_wall``: the piston's;
    the channel's width across the flow is ``p.tank_depth(dx)`` (3-D; in 2-D the liquid's out-of-plane scale, which
    cancels in q per unit width)."""

    def __init__(self, p: Params, dx: float, wall_thickness: float, piston_wall: float) -> None:
        self.dx, self.crest, self.head, self.thickness, self.piston_wall = dx, p.crest_height, p.head, wall_thickness, piston_wall
        self.dim, self.depth = p.dim, p.tank_depth(dx)
        # m^2, a particle's share of the liquid's section in the x-z plane (per unit width across the flow)
        self.cell = dx**2 if p.dim == 2 else dx**3 / self.depth
        self.speed = piston_speed(p.head, p.crest_height)
        self.station = -STATION_HEADS * p.head
        self.strip = STATION_SPACINGS * dx
        start_gap = self.speed * p.duration + PISTON_CLEARANCE_HEADS * p.head + 0.5 * self.strip
        self.piston_face = self.station - start_gap  # at t = 0
        self.length = -self.piston_face + 7.0 * piston_wall  # the channel's -x wall clear of the piston's trailing walls
        self.plate = p.crest_height + 4.0 * p.head  # m, the piston plate's height above the floor

    def tank(self) -> VesselSpec:
        return VesselSpec(name="channel", inner_width=self.length, inner_depth=self.depth, inner_height=self.crest)

    def piston(self) -> VesselSpec:
        """A box whose floor (spanning its inner size plus the walls) is the plate; its walls trail behind. In 3-D the
        plate spans the channel's width between its side walls, the piston's own side walls trailing inside them (a
        plate reaching into the channel's walls would double the wall the liquid in its corners sees)."""
        t = self.piston_wall
        across = self.depth if self.dim == 2 else self.depth - 2.0 * t
        return VesselSpec(name="piston", inner_width=self.plate - 2.0 * t, inner_depth=across, inner_height=4.0 * t, wall_thickness=t)

    def tank_pose(self) -> Pose:
        return Pose((-0.5 * self.length, 0.0, 0.0))

    @property
    def side_height(self) -> float:
        """m, the side plates' height above the crest: up to the piston plate's top, at least three of their walls'
        thickness (a box's floor spans its inner size and two walls)."""
        return max(self.plate - self.crest, 3.0 * self.piston_wall)

    @property
    def top(self) -> float:
        """m, the highest wall above the floor: the piston plate's, or in 3-D the side plates' top."""
        return self.plate if self.dim == 2 else max(self.plate, self.crest + self.side_height)

    def side_plates(self) -> list[tuple[VesselSpec, Pose]]:
        """3-D: the flume's side walls above the crest (the channel's own stand only as high as its weir), from the
        channel's upstream end to the domain's downstream end and :attr:`side_height` high, so that the liquid
        leaves over the weir alone and its nappe stays between side walls, a suppressed weir's. Each is a box turned
        on its side whose floor, the plate, stands on the channel's side wall with its outer face on the wall's inner
        face, its walls trailing outward. None in 2-D."""
        if self.dim == 2:
            return []
        t = self.piston_wall
        x0, x1 = -self.length - self.thickness, self.thickness + DOMAIN_MARGIN
        height = self.side_height
        spec = VesselSpec(name="side", inner_width=x1 - x0 - 2.0 * t, inner_depth=height - 2.0 * t, inner_height=t, wall_thickness=t)
        plates = []
        for sign in (-1.0, 1.0):  # the side at y < 0, then at y > 0; the plate's local +z (its walls) points outward
            turned = np.column_stack([(1.0, 0.0, 0.0), (0.0, 0.0, -sign), (0.0, sign, 0.0)])
            plates.append((spec, Pose((0.5 * (x0 + x1), sign * (0.5 * self.depth + t), self.crest + 0.5 * height), turned)))
        return plates

    def piston_pose(self, t: float) -> Pose:
        """The piston's vessel frame turned -90 deg about y (its +z pointing to -x, its +x up): the floor's outer
        face, the plate, faces the liquid at x = piston_face + U t, its lower edge on the channel's floor."""
        turned = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
        return Pose((self.piston_face - self.piston_wall + self.speed * t, 0.0, 0.5 * self.plate), turned)

    def heads_at_station(self, x: np.ndarray, active: np.ndarray) -> tuple[float, float]:
        """m, the level above the crest in the strip, twice: from the liquid's section area in the strip over its
        width (the measured head), and from the free surface, the top particle of each column dx wide (dx by dx in
        3-D) plus dx/2, averaged over the columns (a check: where the flowing particles have left their lattice, a
        column without a top-row particle reports the row below, so this one reads low by a fraction of dx)."""
        inside = active & (np.abs(x[:, 0] - self.station) < 0.5 * self.strip)
        columns_x = int(round(self.strip / self.dx)) + 1
        column = np.floor((x[inside, 0] - self.station + 0.5 * self.strip) / self.dx).astype(int)
        if self.dim == 3:
            across = int(round(self.depth / self.dx)) + 1
            row = np.clip(np.floor((x[inside, 1] + 0.5 * self.depth) / self.dx).astype(int), 0, across - 1)
            column, columns_x = column * across + row, columns_x * across
        top = np.full(columns_x, -np.inf)
        np.maximum.at(top, column, x[inside, 2])
        surface = float(np.mean(top[np.isfinite(top)])) + 0.5 * self.dx if inside.any() else 0.0
        return float(inside.sum()) * self.cell / self.strip - self.crest, surface - self.crest

    def nappe_surfaces(self, x: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """m above the crest, the nappe's lower and upper surface in bins one spacing wide from the weir's upstream
        face to NAPPE_EXTENT_HEADS nominal heads downstream (:attr:`nappe_x`): the lowest and the highest liquid
        particle centre in the bin (liquid above the crest less NAPPE_DEPTH_HEADS heads) less and plus dx/2; NaN
        where the bin holds none. In 3-D each bin is read so in each column one spacing wide across the channel and
        the columns that hold liquid are averaged: the nappe's surface across its width, as Bazin's profile is the
        section of a nappe uniform across its flume. (The lowest particle over the whole width is the lowest of all
        the columns' readings, each a spacing coarse, and lies under the surface they read together:
        docs/outflow_validation.md.)"""
        bins = len(self.nappe_x)
        over = active & (x[:, 0] >= 0.0) & (x[:, 0] < bins * self.dx) & (x[:, 2] > self.crest - NAPPE_DEPTH_HEADS * self.head)
        column = np.floor(x[over, 0] / self.dx).astype(int)
        across = 1
        if self.dim == 3:
            across = int(round(self.depth / self.dx))
            row = np.clip(np.floor((x[over, 1] + 0.5 * self.depth) / self.dx).astype(int), 0, across - 1)
            column = column * across + row
        lower, upper = np.full(bins * across, np.inf), np.full(bins * across, -np.inf)
        np.minimum.at(lower, column, x[over, 2])
        np.maximum.at(upper, column, x[over, 2])
        lower = np.where(np.isfinite(lower), lower - 0.5 * self.dx - self.crest, np.nan)
        upper = np.where(np.isfinite(upper), upper + 0.5 * self.dx - self.crest, np.nan)
        if across == 1:
            return lower, upper
        return _finite_mean(lower.reshape(bins, across), axis=1), _finite_mean(upper.reshape(bins, across), axis=1)

    @property
    def nappe_x(self) -> np.ndarray:
        """m, the centres of the nappe's bins downstream of the weir's upstream face."""
        return (np.arange(math.ceil(NAPPE_EXTENT_HEADS * self.head / self.dx - 1e-9)) + 0.5) * self.dx

    def passed_area(self, x: np.ndarray, active: np.ndarray) -> float:
        """m^2, the liquid's section area (per unit width) that has passed the weir's upstream face (still beyond it,
        or gone from the domain)."""
        return float(((~active) | (x[:, 0] > 0.0)).sum()) * self.cell


def _finite_mean(a: np.ndarray, axis: int) -> np.ndarray:
    """The mean of ``a`` (finite or NaN) along ``axis`` over its finite entries; NaN where none is (numpy's nanmean,
    without its warning for an all-NaN slice: a bin the nappe did not reach)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(a, axis=axis)


@dataclass(frozen=True)
class Nappe:
    """The nappe's surfaces over the measuring window (m above the crest; x m from the weir's upstream face): per
    bin the mean over the samples in which the bin held liquid (NaN if never), and read off them the lower
    surface's highest point (``rise`` at ``rise_x``), where it passes the crest's level again after it
    (``return_x``, linear between bins; NaN if within the bins it does not), and the upper surface in the first bin
    (``upper_at_weir``)."""

    x: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    rise: float
    rise_x: float
    return_x: float
    upper_at_weir: float


def nappe_profile(x: np.ndarray, lowers: list[np.ndarray], uppers: list[np.ndarray]) -> Nappe:
    """The window's mean nappe from the per-sample surfaces of :meth:`Channel.nappe_surfaces` at bin centres ``x``."""
    def mean(samples: list[np.ndarray]) -> np.ndarray:
        return _finite_mean(np.array(samples, float).reshape(-1, len(x)), axis=0)

    lower, upper = mean(lowers), mean(uppers)
    if not np.isfinite(lower).any():
        return Nappe(x, lower, upper, math.nan, math.nan, math.nan, float(upper[0]))
    k = int(np.nanargmax(lower))
    return_x = math.nan
    for i in range(k, len(x) - 1):
        if lower[i] >= 0.0 > lower[i + 1]:
            return_x = float(x[i] + (x[i + 1] - x[i]) * lower[i] / (lower[i] - lower[i + 1]))
            break
    return Nappe(x, lower, upper, float(lower[k]), float(x[k]), return_x, float(upper[0]))


def run(p: Params) -> CaseResult:
    dx = p.resolved_spacing
    # the kernel's support and the wall model (the domain does not matter to them) set the dummy layers, and so the
    # channel's layout
    depth = p.tank_depth(dx)
    layout = case_fluid_config(p.dim, dx, p.crest_height + p.head, depth, (-1, -1, -1), (1, 1, 1), p.solver, numerics=p.numerics)
    thickness = numerical_wall_thickness(VesselSpec(), layout)  # the channel's walls the liquid sees
    ch = Channel(p, dx, thickness, piston_thickness(layout))
    margin = DOMAIN_MARGIN
    # m, the domain's half extent across the flow: in 3-D past the side plates' trailing walls
    side = depth if p.dim == 2 else 0.5 * depth + max(thickness, 3.0 * ch.piston_wall) + margin
    cfg = case_fluid_config(
        p.dim, dx, p.crest_height + p.head, depth,
        (-ch.length - thickness - margin, -side, -margin), (thickness + margin, side, ch.top + margin), p.solver, numerics=p.numerics,
    )
    block = liquid_block((ch.piston_face, -0.5 * depth, 0.0), (0.0, 0.5 * depth, p.crest_height + p.head), cfg)
    moving = ParticleSet(block.positions, np.tile([ch.speed, 0.0, 0.0], (len(block), 1)), block.densities)
    # the liquid starts moving with the piston, above the crest: nothing holds it for a relaxed start
    plates = ch.side_plates()
    solver = FluidSolver(cfg, [ch.tank(), ch.piston(), *(spec for spec, _ in plates)],
                         [ch.tank_pose(), ch.piston_pose(0.0), *(pose for _, pose in plates)], moving, device=p.device, relax_start=False)
    t, passed, heads, surface_heads, lowers, uppers = [0.0], [0.0], [p.head], [p.head], [], []
    start = time.perf_counter()
    while solver.time < p.duration - 1e-9:
        solver.set_vessel_poses([ch.tank_pose(), ch.piston_pose(solver.time + SAMPLE_INTERVAL), *(pose for _, pose in plates)])
        solver.advance(SAMPLE_INTERVAL)
        x, active = solver.positions(), solver.active_mask()
        t.append(solver.time)
        passed.append(ch.passed_area(x, active))
        head, surface_head = ch.heads_at_station(x, active)
        heads.append(head)
        surface_heads.append(surface_head)
        if solver.time >= p.duration - p.window - 1e-9:
            lower, upper = ch.nappe_surfaces(x, active)
            lowers.append(lower)
            uppers.append(upper)
    wall_time = time.perf_counter() - start
    t, passed, heads, surface_heads = np.array(t), np.array(passed), np.array(heads), np.array(surface_heads)
    window = t >= t[-1] - p.window - 1e-9
    q = float(np.polyfit(t[window], passed[window], 1)[0])
    head15 = float(np.mean(np.clip(heads[window], 0.0, None) ** 1.5))
    head = head15 ** (2.0 / 3.0)
    coefficient = q / (WEIR_FACTOR * head15) if head15 > 0.0 else float("nan")
    surface_head15 = float(np.mean(np.clip(surface_heads[window], 0.0, None) ** 1.5))
    reference = rehbock(head, p.crest_height)
    nappe = nappe_profile(ch.nappe_x, lowers, uppers)
    drift = float(np.polyfit(t[window], heads[window], 1)[0] * p.window)
    metrics = [
        Metric(f"C_d at H0={1e3 * p.head:g} mm", coefficient, reference, (coefficient - reference) / reference, COEFFICIENT_TOLERANCE),
        Metric("head H over the crest", head, p.head, (head - p.head) / p.head, float("inf"), "m"),
        Metric("nappe's lower surface: highest point above the crest", nappe.rise, NAPPE_RISE * head,
               nappe.rise - NAPPE_RISE * head, LIP_TOLERANCE, "m", absolute=True),
    ]
    raw = {
        "t": t.tolist(),
        "passed_area": passed.tolist(),
        "head_series": heads.tolist(),
        "head_by_surface_series": surface_heads.tolist(),
        "discharge": q,
        "head": head,
        "head_drift_in_window": drift,
        "head_by_surface": surface_head15 ** (2.0 / 3.0),
        "coefficient_by_surface_head": q / (WEIR_FACTOR * surface_head15) if surface_head15 > 0.0 else float("nan"),
        "coefficient": coefficient,
        "rehbock": reference,
        "piston_speed": ch.speed,
        "channel_length": ch.length,
        "crest_thickness": thickness,
        "head_over_crest_thickness": head / thickness,
        "nappe_x": nappe.x.tolist(),
        "nappe_lower": nappe.lower.tolist(),
        "nappe_upper": nappe.upper.tolist(),
        "nappe_rise": nappe.rise,
        "nappe_rise_x": nappe.rise_x,
        "nappe_return_x": nappe.return_x,
        "nappe_upper_at_weir": nappe.upper_at_weir,
        "particles": solver.n_particles,
        "steps": solver.step_count,
    }
    params = dict(head=p.head, crest_height=p.crest_height, spacing=dx, dim=p.dim, device=p.device, solver=p.solver.value,
                  duration=p.duration, window=p.window, **({"depth": depth} if p.dim == 3 else {}))
    return CaseResult("outflow", params, metrics, raw, wall_time)


def plot(result: CaseResult, path) -> None:
    r = result.raw
    fig, ax, plt = new_figure(f"Weir ({result.parameters['dim']}-D, P = {result.parameters['crest_height']:g} m): discharge coefficient, "
                              f"H0 = {1e3 * result.parameters['head']:g} mm")
    t, passed, heads = (np.asarray(r[k]) for k in ("t", "passed_area", "head_series"))
    k = max(1, round(0.1 / SAMPLE_INTERVAL))  # 0.1 s differences
    q = (passed[k:] - passed[:-k]) / (t[k:] - t[:-k])
    h15 = np.array([np.mean(np.clip(heads[i : i + k + 1], 0.0, None) ** 1.5) for i in range(len(q))])
    ax.plot(0.5 * (t[k:] + t[:-k]), q / (WEIR_FACTOR * np.maximum(h15, 1e-12)), "-", label="SPH, 0.1 s windows")
    ax.axhline(r["rehbock"], color="k", ls="--", label=f"Rehbock at the measured H: {r['rehbock']:.3f}")
    ax.axhspan(r["rehbock"] * (1 - COEFFICIENT_TOLERANCE), r["rehbock"] * (1 + COEFFICIENT_TOLERANCE), color="0.85")
    ax.axvspan(t[-1] - result.parameters["window"], t[-1], color="g", alpha=0.1, label=f"measured: C_d = {r['coefficient']:.3f}")
    ax.set_ylim(0.0, 1.5)  # room above the curve for the nappe's inset
    ax.set_xlabel("t (s)")
    ax.set_ylabel("C_d = q / ((2/3) sqrt(2g) H^1.5)")
    ax.legend(loc="lower right")
    fig.tight_layout()
    # inset: the nappe's surfaces over the window against Bazin's (heights and distances in units of the head H)
    inset = fig.add_axes((0.2, 0.6, 0.26, 0.24))
    x, lower, upper = (np.asarray(r[k], float) / r["head"] for k in ("nappe_x", "nappe_lower", "nappe_upper"))
    inset.plot(x, lower, "o-", ms=3, label="SPH lower / upper")
    inset.plot(x, upper, "o-", ms=3, color="C0")
    inset.plot([0.0, NAPPE_RISE_AT, NAPPE_RETURN_AT], [0.0, NAPPE_RISE, 0.0], "kx", label="Bazin")
    inset.plot([0.0], [NAPPE_UPPER_AT_WEIR], "kx")
    inset.axhline(0.0, color="0.5", lw=0.8)
    inset.set_xlabel("x / H from the weir", fontsize=7)
    inset.set_ylabel("z / H over the crest", fontsize=7)
    inset.tick_params(labelsize=6)
    inset.legend(fontsize=6, loc="center right")
    fig.savefig(path)
    plt.close(fig)
