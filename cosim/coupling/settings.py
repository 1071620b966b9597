"""Settings of the co-simulation (frozen, validated)."""

from __future__ import annotations

from dataclasses import dataclass

from cosim.checks import check_choice, check_positive, check_range
from enum import Enum


class Coupling(Enum):
    """Whether the arms feel the liquid."""

    TWO_WAY = "two_way"  # the liquid's wrench on each vessel goes into MuJoCo (xfrc_applied)
    ONE_WAY = "one_way"  # arms drive the vessels, the liquid's wrench is measured but not applied


@dataclass(frozen=True)
class CouplingSettings:
    """coupling: :class:`Coupling`.
    wrench_feedforward: the arm controllers feed the measured liquid wrench forward (-J^T w), as an arm with a
        wrist force-torque sensor compensating its payload would; only with two-way coupling.
    start_delay: s, the controller idles this long (catcher pre-positioning) before the pour starts. [0, 10]
    settle_time: s simulated after the controller reports the pour done (the last liquid lands). [0, 10]
    stop_when_done: end the run settle_time after the pour is done (False: always run to max_duration).
    max_duration: s, the run stops here even if the pour is not done. (0, 600]
    """

    coupling: Coupling = Coupling.TWO_WAY
    wrench_feedforward: bool = True
    start_delay: float = 0.2
    settle_time: float = 1.0
    stop_when_done: bool = True
    max_duration: float = 120.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "coupling", check_choice("coupling.coupling", self.coupling, Coupling))
        check_range("coupling.start_delay", self.start_delay, 0.0, 10.0, "s")
        check_range("coupling.settle_time", self.settle_time, 0.0, 10.0, "s")
        check_positive("coupling.max_duration", self.max_duration, "s", 600.0)
