"""A relaxed initial state: the seeded liquid settled in its vessels, held still, before the run starts at t = 0.

A seeded lattice is not the solver's own rest state. Near a free surface (and near a curved wall seeded in rings)
the kernel sums fall short of the rest density rho0; standard DFSPH corrects compression only (the density error
e_i = max(rho_i - rho0, 0), Bender & Koschier 2017, "Divergence-free SPH for incompressible and weakly
compressible fluids", IEEE TVCG), so the surface rows carry no pressure of their own and settle onto the rows
below. Released as seeded, the liquid does that during the run: the surface settles and the column rings for a
while. Here it does it before the run, damped: the vessels are held at their poses, the liquid is advanced
by the solver itself in intervals of ``interval`` s and every particle's velocity is set to zero after each
(the pressure solve's position corrections are kept, the velocity that made them is dropped: a damped dynamic
relaxation, as the particle-packing algorithms of Colagrossi et al. 2012, "Particle packing algorithm for SPH
schemes", Comput. Phys. Commun. 183, damp theirs). Starting from rest, a particle still settling regains up to
g x interval within an interval; one at rest regains only the solve's residual. The relaxation stops at the first
interval in which no particle regained more than ``stop_speed`` (m/s: 'at rest'); where the solve's residual alone
exceeds that (a coarse liquid, a particle jammed in a wall corner that the solve kicks back and forth), once the
largest speed regained has set no new low for ``STALL_TIME`` ('stalled': the settling is over, what is left is the
solve's own motion); or after ``duration`` s ('time cap'). The clock, the step count, the history and the energy
account then restart from the relaxed liquid at rest (:meth:`cosim.fluid.solver.FluidSolver.restart_at_rest`).
Under ``surface_density`` 'seeded_offset' (no offsets when relaxed) the settled top row still sums short of rho0,
resting on the row below in a stacking the compression-only solve holds but that is not stable: released, it drops
into that row's gaps within about half a second (docs/relaxed_start.md). Under 'continuity' (DFSPH's
default) the surface rows keep the density the continuity equation carries to them through the relaxation
(``cosim.fluid.dfsph.surface_offset``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from cosim.fluid.solver import FluidSolver

# Intervals of the relaxation (s): the validation cases' sampling interval; a settling particle gains g x 2 ms =
# 20 mm/s in one, which the stop speed below resolves.
RELAX_INTERVAL = 0.002
# The stop speed as a fraction of g x RELAX_INTERVAL: the liquid is relaxed once no particle gains more than 5 % of
# what free fall would give it within an interval (1 mm/s at g = 9.81 m/s^2).
STOP_SPEED_FRACTION = 0.05
# The relaxation has stalled once the largest speed regained in an interval has set no new low for this long (s):
# longer than the settling of a surface row (20 to 90 intervals in the validation tanks).
STALL_TIME = 0.2
# Longest relaxation (s of simulated time): a liquid that is still moving after it (a column that nothing holds,
# liquid over a rim) is reported as not converged, and its run starts from where it got to, at rest.
RELAX_TIME_CAP = 1.0


@dataclass(frozen=True)
class RelaxationReport:
    """What a relaxation did: intervals and substeps taken, simulated time (s), wall time (s), the largest speed
    (m/s) any particle regained within the last interval, and why it stopped (``outcome``: 'at rest', 'stalled' or
    'time cap')."""

    intervals: int
    substeps: int
    settle_time: float
    wall_time: float
    last_speed: float
    outcome: str

    @property
    def converged(self) -> bool:
        """The liquid came to rest by the stop speed."""
        return self.outcome == AT_REST


AT_REST, STALLED, TIME_CAP = "at rest", "stalled", "time cap"


def stop_speed(gravity: float, interval: float = RELAX_INTERVAL) -> float:
    """m/s: the speed below which a particle counts as at rest after an interval of ``interval`` s from rest,
    ``STOP_SPEED_FRACTION`` of the free-fall gain g x interval (``gravity``: g, m/s^2)."""
    return STOP_SPEED_FRACTION * gravity * interval


def relax_liquid(solver: "FluidSolver", duration: float, interval: float, stop: float, stall: float = math.inf) -> RelaxationReport:
    """Settle ``solver``'s liquid with its vessels held still: intervals of ``interval`` s, the velocities zeroed
    after each, until the largest speed regained in one is below ``stop`` m/s (0: never), it has set no new low
    for ``stall`` s (inf: never), or ``duration`` s have passed; then restart the solver's clock from the liquid at
    rest."""
    steps = max(1, round(duration / interval))
    patience = max(1, round(stall / interval)) if math.isfinite(stall) else steps
    start = time.perf_counter()
    substeps = 0
    speed = lowest = math.inf
    taken = since_low = 0
    while taken < steps and not speed < stop and since_low < patience:
        solver.hold_vessels()
        substeps += solver.advance(interval).substeps
        speed = solver.last_max_speed
        solver.state.v.zero_()
        taken += 1
        since_low = 0 if speed < lowest else since_low + 1
        lowest = min(lowest, speed)
    solver.restart_at_rest()
    outcome = AT_REST if speed < stop else STALLED if since_low >= patience else TIME_CAP
    return RelaxationReport(taken, substeps, taken * interval, time.perf_counter() - start, speed, outcome)
