"""The pourer's discharge coefficient, estimated while it pours: what CFS's feed-forward outflow is scaled by.

Over a sharp crest of length L (the pourer's inner depth) with the liquid h over it, the outflow is the weir law
(Camporredondo et al. 2019, Sec. 2.2)

    Q = (2/3) C_d sqrt(2 g) L h^(3/2)    (m^3/s).

C_d is not a constant of the vessel: the flow toward the crest speeds up and the wall under the crest leans
over as the vessel tilts, and the measured head is that of the highest liquid at the crest. So C_d is estimated
from the pour itself: the ratio of two first-order low-passes with the same time constant, one of the measured
outflow rate dV/dt, one of the weir flow at C_d = 1 of the measured head max(h, 0) (a negative head pours
nothing). Both filters see the same liquid at the same lag, so a change of the head moves both and leaves the
ratio; what moves it is a change of C_d, which follows the tilt over seconds. Both start as if the liquid had
poured at a stated head with the prior coefficient for ever: the estimate starts at the prior and turns into
the measured ratio as the outflow fills the filters, and while nothing flows both decay alike and it stays.
"""

from __future__ import annotations

import math

from controllers.catcher import weir_velocity


def weir_flow(head: float, coefficient: float, crest_length: float, gravity: float) -> float:
    """Q (m^3/s) over a sharp crest of length ``crest_length`` (m) with ``head`` (m) over it: v_q h L, v_q the
    weir velocity (:func:`controllers.catcher.weir_velocity`); 0 for a head <= 0."""
    h = max(head, 0.0)
    return weir_velocity(h, coefficient, gravity) * h * crest_length


class DischargeEstimate:
    """C_d of the pourer's crest from its measured outflow and head (see the module docstring).

    prior: C_d before anything has poured. crest_length: m. head: m, the head the prior stands for in the
    filters. time_constant: s, of both low-passes. gravity: m/s^2.
    """

    def __init__(self, prior: float, crest_length: float, head: float, time_constant: float, gravity: float) -> None:
        self.crest_length = crest_length
        self.time_constant = time_constant
        self.gravity = gravity
        unit = weir_flow(head, 1.0, crest_length, gravity)
        self._outflow = prior * unit  # m^3/s, the measured rate, filtered
        self._weir = unit  # m^3/s, the weir flow at C_d = 1 of the measured head, filtered

    @property
    def coefficient(self) -> float:
        return self._outflow / self._weir

    def update(self, outflow_rate: float, head: float, dt: float) -> None:
        """One measurement: the outflow rate (m^3/s) over the last ``dt`` s and the head (m) at its end."""
        gain = 1.0 - math.exp(-dt / self.time_constant)
        self._outflow += gain * (outflow_rate - self._outflow)
        self._weir += gain * (weir_flow(head, 1.0, self.crest_length, self.gravity) - self._weir)

    def flow(self, head: float) -> float:
        """Q (m^3/s) the weir law gives at ``head`` (m) with the estimated C_d."""
        return weir_flow(head, self.coefficient, self.crest_length, self.gravity)
