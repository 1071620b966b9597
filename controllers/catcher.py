"""The catcher: where the outflow lands (Camporredondo et al. 2019, Eqs. 6-7) and vessel B following it without
large steps.

The jet leaves the pour lip (world x0, z0) with the mean outflow velocity (v_x, v_z) and falls freely:
z = z0 + v_z t - g t^2 / 2 (Eq. 6, the paper takes v_z = 0), x = x0 + v_x t (Eq. 7). It enters vessel B at the
height of B's rim; vessel B moves (along world x only) to put its centre under that point.
"""

from __future__ import annotations

import math

import numpy as np

from controllers.motion import RateLimitedTracker
from controllers.slosh import GRAVITY


def fall_time(drop: float, v_z: float = 0.0, gravity: float = GRAVITY) -> float:
    """Time (s) for a particle launched with vertical velocity ``v_z`` (m/s, up positive) to fall ``drop`` (m).

    The positive root of drop + v_z t - g t^2 / 2 = 0; Eq. 6 with v_z = 0 gives sqrt(2 drop / g). A negative
    drop (launch point below the rim) is treated as zero.
    """
    d = max(drop, 0.0)
    return (v_z + math.sqrt(v_z * v_z + 2.0 * gravity * d)) / gravity


def landing_x(lip_x: float, lip_z: float, rim_z: float, v_x: float, v_z: float = 0.0, gravity: float = GRAVITY) -> float:
    """World x (m) where the jet launched at the lip (lip_x, lip_z) crosses the catcher's rim height ``rim_z``."""
    return lip_x + v_x * fall_time(lip_z - rim_z, v_z, gravity)


def jet_path(
    x0: float, z0: float, v_x: float, v_z: float, drop: float, samples: int = 50, gravity: float = GRAVITY
) -> tuple[np.ndarray, np.ndarray]:
    """World (x, z) m of the jet launched at (x0, z0) with velocity (v_x, v_z) m/s at ``samples`` equal time steps
    until it has fallen ``drop`` m (Eqs. 6-7: z = z0 + v_z t - g t^2 / 2, x = x0 + v_x t)."""
    t = np.linspace(0.0, fall_time(drop, v_z, gravity), samples)
    return x0 + v_x * t, z0 + v_z * t - 0.5 * gravity * t**2


def weir_velocity(h_q: float, discharge_coefficient: float, gravity: float = GRAVITY) -> float:
    """Mean outflow velocity over a sharp crest (Camporredondo et al. 2019, Sec. 2.2): v_q = (2/3) C_d sqrt(2 g h_q) (m/s); 0 if h_q <= 0."""
    return (2.0 / 3.0) * discharge_coefficient * math.sqrt(2.0 * gravity * max(h_q, 0.0))


class CatcherFollower:
    """Vessel B's planar offset dx (m, world x, relative to its home) following the predicted landing point.

    ``home_x``: world x of vessel B's centre (vessel-frame origin) at home. The target dx = landing - home_x,
    low-passed with the time constant ``filter_time`` (s; 0 = none: the SPH jet's prediction jitters from step to
    step, and chasing it shakes the liquid already caught), clipped to [travel_min, travel_max]; the motion is
    rate- and acceleration-limited (max_speed m/s, max_accel m/s^2), so a jump in the prediction never becomes a
    step of the vessel.
    """

    def __init__(
        self,
        home_x: float,
        travel: tuple[float, float],
        max_speed: float,
        max_accel: float,
        dt: float,
        filter_time: float = 0.0,
    ) -> None:
        self.home_x = home_x
        self.travel = travel
        self.tracker = RateLimitedTracker(max_speed, max_accel, dt)
        self.gain = 1.0 if filter_time <= 0.0 else min(dt / filter_time, 1.0)
        self.target_dx = 0.0

    def step(self, landing: float | None) -> float:
        """Advance one control step; ``landing`` (world x, m) updates the target, None keeps the last one."""
        if landing is not None:
            lo, hi = self.travel
            wanted = min(max(landing - self.home_x, lo), hi)
            self.target_dx += self.gain * (wanted - self.target_dx)
        return self.tracker.step(self.target_dx)
