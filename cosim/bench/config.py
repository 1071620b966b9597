"""One benchmark configuration: which case, at which resolution and numerics, on which device (frozen, validated).

A configuration is a pure value: its :meth:`BenchConfig.key` (with the code version) names its cached result.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from enum import Enum

from cosim.checks import check_choice, check_device, check_positive
from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, KernelType, PressureSolver
from cosim.pour_scene import FluidSettings
from declared_settings.setting import check_settings, declared, like


class BenchCase(Enum):
    """What a configuration runs."""

    HYDROSTATIC = "hydrostatic"  # cosim.validation.hydrostatic: pressure against rho0 g (H - z)
    SLOSH = "slosh"  # cosim.validation.slosh: first-mode frequency against Eq. 17 of Camporredondo et al. (2019)
    DAM_BREAK = "dam-break"  # cosim.validation.dam_break: surge front against Martin & Moyce (1952)
    FREE_FALL = "free-fall"  # cosim.validation.free_fall: outflow particles against their free-fall parabolas
    COUPLING_STATIC = "coupling-static"  # cosim.validation.coupling_static: reaction against the liquid's weight
    POUR = "pour"  # the pour scene, compared with another pour run (a finer reference, or the same without a skip)


OptionValue = str | bool | int | float


@dataclass(frozen=True)
class BenchConfig:
    """case: :class:`BenchCase`.
    particles_across: resolution, particles across the case's width (tank width B for hydrostatic and slosh,
        column width a for the dam break, the pourer's inner width for coupling-static and the pour); the scene's
        ``fluid.particles_across`` range.
    length: how long the case runs, in the case's own unit: hydrostatic s held, slosh periods after the pulse,
        dam-break dimensionless time T = t sqrt(2 g / a), free-fall s held after the tilt, coupling-static s held,
        pour s simulated
        (coupling.max_duration). (0, 600]
    device: 'cpu' or 'cuda[:N]'.
    options: pour scene options as (dotted scene key, value) pairs, e.g. (("coupling.coupling", "one_way"),),
        sorted by key; only for the pour.
    dim, kernel, cfl, pressure_solver: the fluid's settings (:class:`cosim.fluid.config.FluidConfig`, its defaults and
        ranges).
    density_tolerance, smoothing_ratio: the fluid's settings where a row sets its own; None: the fluid's default
        (a DFSPH density tolerance only with DFSPH).
    """

    case: BenchCase
    particles_across: int
    length: float
    dim: int = like(FluidConfig, "dim")
    kernel: KernelType = like(FluidConfig, "kernel")
    cfl: float = like(FluidConfig, "cfl")
    pressure_solver: PressureSolver = like(FluidConfig, "pressure_solver")
    device: str = "cpu"
    options: tuple[tuple[str, OptionValue], ...] = ()
    density_tolerance: float | None = like(FluidConfig, "density_tolerance")
    smoothing_ratio: float | None = like(FluidConfig, "smoothing_ratio", None, "the fluid's default")

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "case", check_choice("case", self.case, BenchCase))
        declared(FluidSettings, "particles_across").check("particles_across", self.particles_across)
        check_positive("length", self.length, "", 600.0)
        check_settings(self)
        check_device("device", self.device)
        if self.options and self.case is not BenchCase.POUR:
            raise InputError(f"options: scene options apply to the pour only, not to {self.case.value}")
        s(self, "options", tuple(sorted((str(k), v) for k, v in self.options)))
        if self.density_tolerance is not None and self.pressure_solver is not PressureSolver.DFSPH:
            raise InputError(f"density_tolerance: applies to the dfsph solver only, not to {self.pressure_solver.value}")

    def to_json(self) -> dict:
        """Plain JSON values (enums by value)."""
        return {
            "case": self.case.value, "particles_across": self.particles_across, "length": self.length, "dim": self.dim,
            "kernel": self.kernel.value, "cfl": self.cfl, "pressure_solver": self.pressure_solver.value,
            "device": self.device, "options": [list(o) for o in self.options], "density_tolerance": self.density_tolerance,
            "smoothing_ratio": self.smoothing_ratio,
        }

    def key(self, code_version: str) -> str:
        """Cache key: a hash of every parameter and of ``code_version`` (see :func:`cosim.bench.cache.code_version`)."""
        text = json.dumps({"config": self.to_json(), "code": code_version}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:20]

    @property
    def label(self) -> str:
        """Short human name, e.g. 'pour 2-D 32 wendland_c2 cfl0.25 wcsph cpu coupling=one_way' (DFSPH rows with their
        own density tolerance: ' tol1e-05' after the device; rows with their own smoothing ratio: ' h/dx1.3')."""
        parts = [self.case.value, f"{self.dim}-D", str(self.particles_across), self.kernel.value, f"cfl{self.cfl:g}",
                 self.pressure_solver.value, self.device]
        if self.density_tolerance is not None:
            parts.append(f"tol{self.density_tolerance:g}")
        if self.smoothing_ratio is not None:
            parts.append(f"h/dx{self.smoothing_ratio:g}")
        parts += [f"{k.rsplit('.', 1)[-1]}={v}" for k, v in self.options]
        return " ".join(parts)
