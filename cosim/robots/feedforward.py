"""The servo feedforward choices of a replay (:mod:`cosim.robots.replay`), in a module of their own so that
``cosim replay --help`` can list them without loading MuJoCo."""

from __future__ import annotations

from enum import Enum


class Feedforward(Enum):
    """Closed choice of servo feedforward on top of the PD law."""

    GRAVITY = "gravity"  # model gravity compensation only
    DYNAMICS = "dynamics"  # plus inverse dynamics of the commanded motion
