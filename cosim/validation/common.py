"""Shared pieces of the validation cases: the result record, the common fluid set-up, plotting helpers."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from cosim.checks import check_device
from cosim.errors import InputError
from cosim.fluid.config import GRAVITY, FluidConfig, PressureSolver
from declared_settings.setting import check_settings, declared, like

# FluidConfig fields a case's numerics may override (the rest is the case's geometry, physics and solver).
NUMERICS_FIELDS = (
    "kernel", "smoothing_ratio", "cfl", "sound_speed_factor", "free_liquid", "free_liquid_rule", "free_surface_threshold", "density_iteration",
    "density_tolerance", "wall_model", "artificial_viscosity", "artificial_viscosity_scale", "free_artificial_viscosity", "artificial_viscosity_beta",
    "initial_state", "surface_density", "wall_pressure", "divergence_constraint", "max_tension", "tension_treatment", "density_diffusion_term", "particle_shifting",
    "shifting_coefficient", "viscous_time_step",
)


@dataclass(frozen=True)
class Metric:
    """One compared quantity. ``error`` is relative ((measured - reference) / reference) unless ``absolute``."""

    name: str
    measured: float
    reference: float
    error: float
    tolerance: float
    unit: str = ""
    absolute: bool = False

    @property
    def passed(self) -> bool:
        return bool(abs(self.error) <= self.tolerance)


@dataclass
class CaseResult:
    """The outcome of one validation run: compared metrics, raw series (JSON-ready) and the wall time."""

    case: str
    parameters: dict[str, Any]
    metrics: list[Metric]
    raw: dict[str, Any] = field(default_factory=dict)
    wall_time: float = 0.0

    @property
    def passed(self) -> bool:
        return all(m.passed for m in self.metrics)

    def to_json(self) -> dict[str, Any]:
        out = {"case": self.case, "passed": self.passed, "wall_time_s": self.wall_time, "parameters": self.parameters}
        out["metrics"] = [dict(asdict(m), passed=m.passed) for m in self.metrics]
        out.update(self.raw)
        return out


@dataclass(frozen=True)
class FluidCaseParams:
    """Parameters every fluid case shares (overridable from the command line).

    device: 'cpu' or 'cuda[:N]'.
    depth: m, tank depth perpendicular to the pour plane (3-D extent, rounded to whole spacings by
        :meth:`tank_depth`; 2-D out-of-plane scale).
    solver: pressure solver, :class:`PressureSolver` or its name ('wcsph', 'dfsph').
    numerics: overrides of the solver's numerical settings, (FluidConfig field, value) pairs, e.g.
        (("kernel", "cubic_spline"), ("cfl", 0.4)); one of NUMERICS_FIELDS each (the benchmark's axes).
    """

    spacing: float | None = like(FluidConfig, "spacing", None, "the case's default resolution")
    dim: int = like(FluidConfig, "dim")
    device: str = "cpu"
    depth: float = FluidConfig.depth_2d
    solver: PressureSolver = FluidConfig.pressure_solver
    numerics: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        """The shared parameters checked, then the declared ones, the shared and the case's own (:func:`check_settings`)."""
        check_device("device", self.device)
        declared(FluidConfig, "depth_2d").check("depth", self.depth)
        object.__setattr__(self, "solver", declared(FluidConfig, "pressure_solver").check("solver", self.solver))
        for name, _ in self.numerics:
            if name not in NUMERICS_FIELDS:
                raise InputError(f"numerics: {name!r} cannot be overridden; choose from {', '.join(NUMERICS_FIELDS)}")
        # the values' own range checks and those between settings (under the case's solver), before anything runs
        FluidConfig(pressure_solver=self.solver, **dict(self.numerics))
        check_settings(self)

    def tank_depth(self, spacing: float) -> float:
        """m, the tank depth the case builds: in 3-D ``depth`` in whole spacings (:func:`whole_spacings`); in 2-D
        ``depth`` only scales the liquid out of the plane and is kept."""
        return self.depth if self.dim == 2 else whole_spacings(self.depth, spacing)


def whole_spacings(length: float, spacing: float) -> float:
    """m, a tank's ``length`` rounded to a whole number of ``spacing`` (at least one; kept where it is one already, to
    1e-9 of a spacing), so that the seeded lattice fills the tank across. A remainder would leave the outer columns a
    gap to the wall, and the liquid would stand taller than its volume over the floor area (the hydrostatic error
    this causes: docs/physics-and-validation.md)."""
    count = max(1, round(length / spacing))
    return length if abs(length / spacing - count) <= 1e-9 else count * spacing


def reference_speed(liquid_height: float) -> float:
    """The expected maximum liquid speed (m/s) of a scene whose tallest liquid column is ``liquid_height`` (m):
    twice the shallow-water wave speed, 2 sqrt(g H) (Ritter's dam-break front speed), the same rule for every
    case so that no case is tuned on its own."""
    return 2.0 * math.sqrt(GRAVITY * liquid_height)


def case_fluid_config(
    dim: int, spacing: float, liquid_height: float, depth: float, domain_min, domain_max, solver: PressureSolver = FluidConfig.pressure_solver,
    numerics=(),
) -> FluidConfig:
    """The fluid configuration every case uses: project defaults (or ``numerics``, see :class:`FluidCaseParams`),
    c0 from :func:`reference_speed`."""
    return FluidConfig(
        dim=dim,
        pressure_solver=solver,
        spacing=spacing,
        max_expected_speed=reference_speed(liquid_height),
        depth_2d=depth,
        domain_min=tuple(domain_min),
        domain_max=tuple(domain_max),
        **dict(numerics),
    )


def require_particles_across(name: str, width: float, spacing: float, minimum: int) -> None:
    if width < (minimum - 1e-9) * spacing:  # a product: a spacing that underflowed to 0 is no division by zero
        raise InputError(f"{name}: spacing {spacing:g} m gives {width / spacing:.1f} particles across {width:g} m; needs >= {minimum}")


def zero_crossing_frequency(t: np.ndarray, signal: np.ndarray) -> tuple[float, int]:
    """Frequency (Hz) from the mean period between same-direction zero crossings (linear interpolation) of a
    mean-removed signal, and the number of full periods it used."""
    y = signal - signal.mean()
    idx = np.nonzero((y[:-1] < 0.0) & (y[1:] >= 0.0))[0]
    if len(idx) < 2:
        return float("nan"), 0
    crossings = t[idx] - y[idx] * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])
    periods = len(crossings) - 1
    return periods / (crossings[-1] - crossings[0]), periods


def new_figure(title: str):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5), dpi=110)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    return fig, ax, plt
