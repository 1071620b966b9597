"""Validation cases of the fluid core (and, once the robots exist, of the coupling) against analytic solutions
and published experiments. Each case provides frozen, validated parameters, ``run(params) -> CaseResult`` and
``plot(result, path)``; :data:`CASES` is the registry ``cosim validate`` drives."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from cosim.validation import coupling_static, dam_break, free_fall, hydrostatic, moving_vessel, slosh
from cosim.validation.common import CaseResult


@dataclass(frozen=True)
class Case:
    """A validation case: its parameter class, runner and plotter."""

    params: type
    run: Callable[[Any], CaseResult]
    plot: Callable[[CaseResult, Any], None]
    summary: str


CASES: dict[str, Case] = {
    "hydrostatic": Case(hydrostatic.Params, hydrostatic.run, hydrostatic.plot, "resting tank: p = rho0 g (H - z)"),
    "slosh": Case(slosh.Params, slosh.run, slosh.plot, "first sloshing mode vs seed Eq. 17"),
    "dam-break": Case(dam_break.Params, dam_break.run, dam_break.plot, "surge front vs Martin & Moyce (1952)"),
    "tilt": Case(moving_vessel.Params, moving_vessel.run_tilt, moving_vessel.plot, "full vessel tilted about its lip"),
    "coupling-static": Case(
        coupling_static.Params, coupling_static.run, coupling_static.plot, "held full vessel: reaction and joint torques"
    ),
    "shake": Case(moving_vessel.Params, moving_vessel.run_shake, moving_vessel.plot, "full vessel shaken at resonance"),
    "free-fall": Case(free_fall.Params, free_fall.run, free_fall.plot, "outflow particles vs their free-fall parabolas (seed Eqs. 6-7)"),
}
DEFAULT_CASES = ("hydrostatic", "slosh", "dam-break", "free-fall", "coupling-static")
