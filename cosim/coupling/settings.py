"""Settings of the co-simulation (frozen, validated)."""

from __future__ import annotations

from dataclasses import dataclass

from cosim.checks import check_choice, check_positive, check_range
from enum import Enum


class Coupling(Enum):
    """Whether the arms feel the liquid."""

    TWO_WAY = "two_way"  # the liquid's wrench on each vessel goes into MuJoCo (xfrc_applied)
    ONE_WAY = "one_way"  # arms drive the vessels, the liquid's wrench is measured but not applied


class Compensation(Enum):
    """What each arm's controller knows of the liquid it holds and feeds forward (two-way coupling only); the rest of
    the liquid's wrench acts on the servos (:mod:`cosim.coupling.compensation`)."""

    STATIC_PAYLOAD = "static_payload"  # the liquid's mass and centre of mass at the start, as a UR's payload setting
    UPDATED_PAYLOAD = "updated_payload"  # the same, re-set to the liquid left every control period (UR set_payload)
    IDEAL_FORCE_TORQUE = "ideal_force_torque"  # the measured wrench itself: a perfect wrist force-torque sensor
    NONE = "none"  # nothing: the servos carry the whole liquid


@dataclass(frozen=True)
class CouplingSettings:
    """coupling: :class:`Coupling`.
    compensation: :class:`Compensation`, what the arms feed forward of the liquid's load (two-way coupling only).
    start_delay: s, the controller idles this long (catcher pre-positioning) before the pour starts. [0, 10]
    settle_time: s simulated after the controller reports the pour done (the last liquid lands). [0, 10]
    stop_when_done: end the run settle_time after the pour is done (False: always run to max_duration).
    max_duration: s, the run stops here even if the pour is not done. (0, 600]
    """

    coupling: Coupling = Coupling.TWO_WAY
    compensation: Compensation = Compensation.STATIC_PAYLOAD
    start_delay: float = 0.2
    settle_time: float = 1.0
    stop_when_done: bool = True
    max_duration: float = 120.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "coupling", check_choice("coupling.coupling", self.coupling, Coupling))
        object.__setattr__(self, "compensation", check_choice("coupling.compensation", self.compensation, Compensation))
        check_range("coupling.start_delay", self.start_delay, 0.0, 10.0, "s")
        check_range("coupling.settle_time", self.settle_time, 0.0, 10.0, "s")
        check_positive("coupling.max_duration", self.max_duration, "s", 600.0)
