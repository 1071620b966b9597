"""The servo feedforward choices and the default path tolerance of a replay (:mod:`cosim.trajectory.replay`), in a
module of their own so that ``cosim replay --help`` can show them without loading MuJoCo."""

from __future__ import annotations

from enum import Enum

# m: the default tolerance of the lips' path error. A pour lip 2 mm off its path moves the stream's landing point by
# about as much, small against the catcher's opening (0.26 m in the default scene).
DEFAULT_TOLERANCE_M = 0.002


class Feedforward(Enum):
    """Closed choice of servo feedforward on top of the PD law."""

    GRAVITY = "gravity"  # model gravity compensation only
    DYNAMICS = "dynamics"  # plus inverse dynamics of the commanded motion
