"""Which configurations the benchmark runs: axes around the default scene's settings, not hand-written rows.

Per case: a resolution sweep at the default numerics, then one axis at a time at the case's default resolution
(the pour: at 24 across) (every other kernel, the CFL levels, the smoothing ratios h / dx), and every other pressure solver over the whole
resolution sweep (to compare the solvers at equal error); on every device present. The pour adds a
fine reference (:data:`REFERENCE_ACROSS`, :data:`REFERENCE_SOLVER`) that its resolution and numerics rows are compared with, and the skip
options: pairs of runs that differ only in what a scene may skip, the second doing the full work.

Cost: the full plan finishes cold in about 40 minutes on a 2-core CPU, a third of it the 48-across WCSPH
reference. The pour rows compared with the reference run the whole pour (the early stop ends each when its pour is
done, at most :data:`POUR_SECONDS`), every one at the default scene's CFS head (:func:`equal_head_options`): a window
that ends before the outflow would rank them by the onset of the outflow alone, and a head that follows the
resolution by the controller's set point. The skip-option pairs, which compare two runs with each other, run
:data:`SKIP_PAIR_SECONDS`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from cosim.bench.config import BenchCase, BenchConfig
from cosim.fluid.config import KernelType, PressureSolver
from cosim.fluid.runtime import cuda_available
from cosim.pour_scene import FluidSettings

# s, max_duration of the pour rows compared with the reference: the whole pour, which the early stop ends when it is
# done (at the default's head: 18 to 23 s at 16, 32 and 48 across; the 24-across pour is not done by this bound and
# is compared over the 24 s it ran, cosim.bench.pour_compare)
POUR_SECONDS = 24.0
SKIP_PAIR_SECONDS = 3.0  # s simulated by each skip-option pair at 24 across (the slosh induction and the outflow's onset)
REFERENCE_ACROSS = 48  # particles across the pourer of the reference pour (1.5 x the default scene's 32)
# The reference pour's pressure solver: WCSPH whatever the default scene's solver is. A reference computed with the
# default's own solver would favour the default in the equal-error comparison of the two solvers; a WCSPH
# reference favours, if anything, the solver the default does not use.
REFERENCE_SOLVER = PressureSolver.WCSPH
CFL_LEVELS = (0.15, 0.4)  # besides the default 0.25 (the stress matrix goes to twice the default)
# DFSPH's density-solve tolerance besides the default (Gauss-Seidel's 1.5e-4), at each case's default resolution: its
# iterations are about half of a DFSPH substep, so it is the solver's own speed-against-error knob
DENSITY_TOLERANCE_LEVELS = (5.0e-5, 1.0e-4, 3.0e-4)
# h / dx besides the default 1.5 (FluidConfig.smoothing_ratio), at each case's default resolution: fewer neighbours per
# particle (in 3-D the pair work of a substep goes as the cube of the ratio) against the kernel's accuracy; a smaller
# ratio also shortens the time step, a larger one lengthens it
SMOOTHING_RATIO_LEVELS = (1.3, 1.8)
DIM_PAIR_SECONDS = 2.0  # s simulated by the 2-D/3-D pair at 16 across (3-D costs about 30 x 2-D there)


@dataclass(frozen=True)
class CaseAxes:
    """resolutions: particles across, coarse to the case default (the last). length: the case's run length
    (see :class:`BenchConfig`). cfl_levels: the CFL numbers tried besides the default. axes_at: the resolution of
    the one-axis-at-a-time rows (None: the case default)."""

    resolutions: tuple[int, ...]
    length: float
    cfl_levels: tuple[float, ...] = CFL_LEVELS
    axes_at: int | None = None


# Resolution sweeps end at each case's own default resolution (cosim.validation: 40 across the tank, 50 across
# the dam-break column, 32 across the pourer for free-fall, 24 across the pourer for coupling-static; the default
# scene: 32 across the pourer).
FULL_AXES = {
    BenchCase.HYDROSTATIC: CaseAxes((20, 30, 40), 1.0),  # s held (the validation holds 2 s)
    BenchCase.SLOSH: CaseAxes((20, 30, 40), 3.0),  # periods (the validation measures 5), fill A = 0.108 m
    BenchCase.DAM_BREAK: CaseAxes((25, 50), 3.0),  # T up to the acceptance window's end
    BenchCase.FREE_FALL: CaseAxes((16, 24, 32), 1.0),  # s held after the tilt (as the validation)
    BenchCase.COUPLING_STATIC: CaseAxes((16, 24), 0.5),  # s held
    # the pour varies kernel, CFL and solver at 24 across (32 costs about 2.8 x more) and leaves out CFL 0.15 (1.7 x
    # the cost), to keep the plan within its budget
    BenchCase.POUR: CaseAxes((16, 24, 32), POUR_SECONDS, cfl_levels=(0.4,), axes_at=24),
}
SMOKE_AXES = {  # seconds of CPU: for tests and a quick check of the machinery, not for numbers
    BenchCase.HYDROSTATIC: CaseAxes((8,), 0.02),
    BenchCase.DAM_BREAK: CaseAxes((8,), 1.0),
}


@dataclass(frozen=True)
class SkipOption:
    """A scene option that skips work (or spreads it over the cores): ``skip`` runs with it, ``full`` without
    (everything else equal)."""

    name: str
    setting: str
    skip: BenchConfig
    full: BenchConfig


@dataclass(frozen=True)
class BenchPlan:
    """rows: every configuration to run, in order, without duplicates. defaults: per case, the configuration with
    the default scene's settings. reference: the fine pour the pour rows are compared with (None without pours).
    skips: the skip-option pairs."""

    rows: tuple[BenchConfig, ...]
    defaults: dict[BenchCase, BenchConfig]
    reference: BenchConfig | None = None
    skips: tuple[SkipOption, ...] = ()

    def compared_pours(self) -> list[BenchConfig]:
        """Pour rows compared with the reference: every other pour row of the same length."""
        ref = self.reference
        return [c for c in self.rows if ref is not None and c.case is BenchCase.POUR and c.length == ref.length and c != ref]


def default_numerics(device: str = "cpu") -> dict:
    """The default scene's numerical settings (pour_scene.FluidSettings, the solver's default pressure solver)."""
    scene = FluidSettings()
    return {"dim": scene.dim, "kernel": scene.kernel, "cfl": scene.cfl, "pressure_solver": scene.pressure_solver,
            "device": device}


def equal_head_options() -> tuple[tuple[str, float], ...]:
    """Scene options that make every pour row hold the default scene's CFS head (m over the crest).

    Left to itself a scene holds at least ``controller.stream_particles`` spacings over the crest
    (:func:`cosim.pour_run.cfs_head_reference`): 17.9 mm at the default 32 across, 11.9 at the reference's 48 and
    23.9 at 24. A weir's outflow goes as the head^(3/2), so each resolution would pour at its own rate (the 48-across
    reference at 0.54 x the default's) and the rows would differ by the controller's set point, not by the
    numerics. With these options every row holds the default's head and no floor: the same commanded pour. The
    default row is the default scene's pour (the same head); rows coarser than the default hold fewer than
    ``stream_particles`` spacings, a stream the weir case does not resolve, and their errors include that."""
    from cosim.pour_run import cfs_head_reference
    from cosim.pour_scene import PourScene

    scene = PourScene()
    head = cfs_head_reference(scene, scene.vessels.pourer.inner_width / scene.fluid.particles_across)
    return (("controller.cfs.h_q_ref", head), ("controller.stream_particles", 0.0))


def _case_options(case: BenchCase) -> tuple[tuple[str, float], ...]:
    """Options every row of ``case`` carries (the pour's equal head; none for the validation cases)."""
    return equal_head_options() if case is BenchCase.POUR else ()


def _axis_rows(case: BenchCase, axes: CaseAxes, device: str) -> list[BenchConfig]:
    base = BenchConfig(case, axes.axes_at or axes.resolutions[-1], axes.length, options=_case_options(case),
                       **default_numerics(device))
    rows = [replace(base, particles_across=n) for n in axes.resolutions]
    rows += [replace(base, kernel=k) for k in KernelType if k is not base.kernel]
    rows += [replace(base, cfl=c) for c in axes.cfl_levels if c != base.cfl]
    rows += [replace(base, smoothing_ratio=r) for r in SMOOTHING_RATIO_LEVELS]
    if base.pressure_solver is PressureSolver.DFSPH:
        rows += [replace(base, particles_across=axes.resolutions[-1], density_tolerance=t) for t in DENSITY_TOLERANCE_LEVELS]
    # every other pressure solver over the whole resolution sweep, so the two can be compared at equal error
    rows += [replace(base, particles_across=n, pressure_solver=s) for s in PressureSolver if s is not base.pressure_solver for n in axes.resolutions]
    return rows


def _skip_options(device: str) -> list[SkipOption]:
    d = default_numerics(device)
    at = {n: BenchConfig(BenchCase.POUR, n, SKIP_PAIR_SECONDS, options=equal_head_options(), **d) for n in (16, 24)}

    def opt(cfg: BenchConfig, key: str, value) -> BenchConfig:
        return replace(cfg, options=cfg.options + ((key, value),))

    # both at the default scene's CFS head (equal_head_options), so that the pair differs only in the liquid's
    # dimension, not in the head floor that follows it (pour_scene.STREAM_PARTICLES)
    flat = replace(at[16], length=DIM_PAIR_SECONDS)
    # the early-stop pair is the default pour itself (the run without the stop goes on to POUR_SECONDS; the default
    # scene's 60 s would cost 2.8 x more): a coarser pour may not be done by POUR_SECONDS, and then the pair would
    # compare two runs doing the same work
    full_stop = BenchConfig(BenchCase.POUR, FluidSettings().particles_across, POUR_SECONDS, options=equal_head_options(), **d)
    return [
        SkipOption("2-D liquid in the pour plane", "fluid.dim = 2 (full: 3; both at the default scene's CFS head)",
                   flat, replace(flat, dim=3)),
        SkipOption("SIM only when the fill needs it", "controller.sim.mode = auto (full: always)", at[24],
                   opt(at[24], "controller.sim.mode", "always")),
        SkipOption("one-way coupling", "coupling.coupling = one_way (full: two_way)",
                   opt(at[24], "coupling.coupling", "one_way"), at[24]),
        SkipOption("logging off", "logging.enabled = false (full: true, every particle at 30 Hz)", at[24],
                   opt(at[24], "logging.enabled", True)),
        SkipOption("early stop when the pour is done", "coupling.stop_when_done = true (full: false)", full_stop,
                   opt(full_stop, "coupling.stop_when_done", False)),
        SkipOption("adaptive time step", "fluid.adaptive_time_step = true (full: false, the fixed step of the expected "
                   "speed)", at[24], opt(at[24], "fluid.adaptive_time_step", False)),
        SkipOption("neighbour grid restricted to the liquid", "fluid.grid_reset = occupied (full: whole)", at[24],
                   opt(at[24], "fluid.grid_reset", "whole")),
        SkipOption("Gauss-Seidel density solve", "fluid.density_iteration = gauss_seidel (full: jacobi, each at its default tolerance)",
                   at[24], opt(at[24], "fluid.density_iteration", "jacobi")),
        SkipOption("substeps split over the CPU cores", "fluid.cpu_threads = 0, one per core (full: 1)", at[24],
                   opt(at[24], "fluid.cpu_threads", 1)),
    ]


def build_plan(name: str = "full") -> BenchPlan:
    """The 'full' plan (the numbers in docs/benchmarks.md) or the 'smoke' plan (tiny, seconds); CPU rows always,
    CUDA rows when a CUDA device is present."""
    devices = ["cpu"] + (["cuda"] if cuda_available() else [])
    axes = FULL_AXES if name == "full" else SMOKE_AXES
    rows: list[BenchConfig] = []
    defaults = {}
    reference, skips = None, []
    for case, case_axes in axes.items():
        for device in devices:
            rows += _axis_rows(case, case_axes, device)
        defaults[case] = BenchConfig(case, case_axes.resolutions[-1], case_axes.length, options=_case_options(case),
                                     **default_numerics())
    if BenchCase.POUR in axes:
        reference = replace(defaults[BenchCase.POUR], particles_across=REFERENCE_ACROSS, pressure_solver=REFERENCE_SOLVER)
        skips = _skip_options("cpu")
        rows = [reference] + rows + [c for s in skips for c in (s.skip, s.full)]
    unique = list(dict.fromkeys(rows))
    return BenchPlan(tuple(unique), defaults, reference, tuple(skips))
