"""Outcome of a stress configuration from its measurements.

``instability``: the solver stopped with its :class:`~cosim.fluid.solver.FluidInstabilityError` (a clear error:
acceptable). ``silent``: the run finished but produced garbage (the outcome that must never occur): any of
non-finite values, a leaked particle, a density error past the solver's own bound, or energy the numerics created
past :data:`ENERGY_EXCESS_BOUND`. ``clean``: none of these. ``refused``: the solver refused the configuration
at set-up with its one-line input error (a liquid the particles cannot resolve, cosim.fluid.seeding.check_resolution;
acceptable: nothing was simulated). ``error``: anything else went wrong (an unexpected exception: a failure of the
product, recorded by the caller).
"""

from __future__ import annotations

from enum import Enum

from cosim.errors import count_of
from cosim.fluid.config import FluidConfig
from cosim.stress.runner import Measurement


class Outcome(Enum):
    CLEAN = "clean"
    INSTABILITY = "instability"
    SILENT = "silent"
    REFUSED = "refused"
    ERROR = "error"


FAILURES = (Outcome.SILENT, Outcome.ERROR)  # outcomes that fail `cosim stress`

# |rho - rho0| / rho0 past which a finished run is garbage: the solver's own bound on compression
# (FluidConfig.max_density_error, DualSPHysics' +-30 % validity range), applied to both signs.
DENSITY_ERROR_BOUND = FluidConfig().max_density_error
# Energy the numerics may create, (E - E0 - W) / (M g L), before a finished run is garbage: the solver's own bound
# (FluidConfig.max_energy_creation, which its energy account enforces as an instability; this measurement is the
# independent check of that account, from the particles read back after each interval).
ENERGY_EXCESS_BOUND = FluidConfig().max_energy_creation


def garbage_reasons(m: Measurement) -> list[str]:
    """What makes ``m`` garbage (empty: nothing)."""
    reasons = []
    if m.nonfinite > 0:
        reasons.append(f"{count_of(m.nonfinite, 'particle')} with non-finite values")
    if m.leaked > 0:
        reasons.append(f"{count_of(m.leaked, 'particle')} leaked (inside {m.worst_inside}, through {m.worst_through}, "
                       f"escaped {m.worst_escaped} at worst)")
    if not m.max_density_error <= DENSITY_ERROR_BOUND:  # NaN counts as past the bound
        reasons.append(f"density error {m.max_density_error:.3g} > {DENSITY_ERROR_BOUND:g}")
    if not m.energy_excess <= ENERGY_EXCESS_BOUND:
        reasons.append(f"energy created {m.energy_excess:.3g} M g L > {ENERGY_EXCESS_BOUND:g}")
    return reasons


def classify(m: Measurement) -> tuple[Outcome, str]:
    """(outcome, message): the instability's message, or why the result is garbage ('' when clean)."""
    if m.failure:
        return Outcome.INSTABILITY, m.failure
    reasons = garbage_reasons(m)
    return (Outcome.SILENT, "; ".join(reasons)) if reasons else (Outcome.CLEAN, "")
