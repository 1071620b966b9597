"""Validation cases of the fluid core (and, once the robots exist, of the coupling) against analytic solutions
and published experiments. Each case provides frozen, validated parameters, ``run(params) -> CaseResult`` and
``plot(result, path)``; :data:`CASES` is the registry ``cosim validate`` drives. A case's module (and with it warp
and MuJoCo) is imported when the case is used, not when the registry is read."""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any, Callable

if TYPE_CHECKING:
    from cosim.validation.common import CaseResult


@dataclass(frozen=True)
class Case:
    """A validation case: the module implementing it (``cosim.validation.<module>``, with its ``Params`` and
    ``plot``), the name of its runner there, and a one-line summary."""

    module: str
    runner: str
    summary: str

    def implementation(self) -> ModuleType:
        return importlib.import_module(f"{__name__}.{self.module}")

    @property
    def params(self) -> type:
        return self.implementation().Params

    @property
    def run(self) -> Callable[[Any], CaseResult]:
        return getattr(self.implementation(), self.runner)

    @property
    def plot(self) -> Callable[[CaseResult, Any], None]:
        return self.implementation().plot


CASES: dict[str, Case] = {
    "hydrostatic": Case("hydrostatic", "run", "resting tank: p = rho0 g (H - z)"),
    "slosh": Case("slosh", "run", "first sloshing mode vs linear theory (Eq. 17)"),
    "dam-break": Case("dam_break", "run", "surge front vs Martin & Moyce (1952)"),
    "tilt": Case("moving_vessel", "run_tilt", "full vessel tilted about its lip"),
    "coupling-static": Case("coupling_static", "run", "held full vessel: reaction and joint torques"),
    "shake": Case("moving_vessel", "run_shake", "full vessel shaken at resonance"),
    "slosh-plant": Case("slosh_plant", "run", "slosh pendulum (omega1, hinge, damping) from tilts vs potential flow"),
    "free-fall": Case("free_fall", "run", "outflow particles vs their free-fall parabolas (Camporredondo et al. 2019, Eqs. 6-7)"),
    "outflow": Case("weir", "run", "steady flow over a sharp-crested weir: discharge coefficient vs Rehbock, nappe vs Bazin (2-D or 3-D)"),
}
DEFAULT_CASES = ("hydrostatic", "slosh", "dam-break", "free-fall", "coupling-static")
