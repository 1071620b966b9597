"""What stops a run: the checks of an interval's substep diagnostics and the error they raise."""

from __future__ import annotations

import numpy as np

from cosim.errors import SimulationError, count_of
from cosim.fluid.config import FluidConfig
from cosim.fluid.diagnostics import DIAG_BREACHES, DIAG_NONFINITE, DIAG_PAIR_OVERFLOW, SubstepRows

# the int columns of which any nonzero count stops the run
_STOPPING_COUNTS = np.array([DIAG_NONFINITE, DIAG_BREACHES, DIAG_PAIR_OVERFLOW])


class FluidInstabilityError(SimulationError):
    """The liquid broke: non-finite values, density error past its bound, a wall breached, a collapsed step."""

    def __init__(self, step: int, time: float, reason: str):
        super().__init__(f"SPH step {step} (t = {time:.5f} s): {reason}")
        self.step = step
        self.time = time
        self.reason = reason


def check_interval(cfg: FluidConfig, rows: SubstepRows, first: int, t0: float, dt: float, energy_created: float) -> None:
    """Raises :class:`FluidInstabilityError` for the first substep of the interval (substep number ``first`` onward,
    starting at ``t0`` s, each ``dt`` s) that has a particle with a non-finite state, one deeper in a wall than
    ``max_wall_penetration``, one with more neighbours than its pair list holds, or a compression past
    ``max_density_error``; else for the interval's end where the energy the numerics created, ``energy_created``
    (M g L), exceeds ``max_energy_creation``."""
    if not (
        rows.i[:, _STOPPING_COUNTS].any() or np.maximum.reduce(rows.max_compression) > cfg.max_density_error or energy_created > cfg.max_energy_creation
    ):  # the usual interval, found in one pass
        return
    checks = [
        (rows.nonfinite > 0, lambda s: f"{count_of(rows.nonfinite[s], 'particle')} with a non-finite position, velocity or density"),
        (
            rows.wall_breaches > 0,
            lambda s: f"{count_of(rows.wall_breaches[s], 'particle')} inside a vessel wall (deeper than {cfg.max_wall_penetration:g} dx)",
        ),
        (
            rows.pair_overflows > 0,
            lambda s: f"{count_of(rows.pair_overflows[s], 'particle')} with more neighbours than the pair list holds (over-compressed)",
        ),
        (
            rows.max_compression > cfg.max_density_error,
            lambda s: f"compression {rows.max_compression[s]:.3f} exceeds fluid.max_density_error = {cfg.max_density_error:g}",
        ),
    ]
    bad = [(int(np.argmax(mask)), describe) for mask, describe in checks if mask.any()]
    if bad:
        s, describe = min(bad, key=lambda b: b[0])
        raise FluidInstabilityError(first + s, t0 + (s + 1) * dt, describe(s))
    if energy_created > cfg.max_energy_creation:
        s = len(rows) - 1
        raise FluidInstabilityError(
            first + s, t0 + (s + 1) * dt,
            f"the numerics created {energy_created:.3g} M g L of energy beyond the walls' work "
            f"(fluid.max_energy_creation = {cfg.max_energy_creation:g}); a finer fluid.spacing, a larger "
            "fluid.sound_speed_factor or a gentler vessel motion",
        )
