"""The sampled joint trajectory that the generator records, the checks verify and the file formats write.

Units: s, rad, rad/s, rad/s^2. Joint names are the scene's ``<arm>/<joint>`` (``pour_arm/shoulder_pan``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from cosim.errors import InputError

MIN_SAMPLES = 2


@dataclass(frozen=True)
class JointTrajectory:
    """A sampled joint trajectory.

    time: (N,) s, strictly increasing, N >= 2.
    joint_names: (J,) full joint names ``<arm>/<joint>``, unique.
    positions, velocities, accelerations: (N, J) rad, rad/s, rad/s^2, finite.
    """

    time: np.ndarray
    joint_names: tuple[str, ...]
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray

    def __post_init__(self) -> None:
        time = np.asarray(self.time, dtype=float)
        names = tuple(self.joint_names)
        if time.ndim != 1 or time.size < MIN_SAMPLES:
            raise InputError(f"trajectory.time: must hold at least {MIN_SAMPLES} samples, got shape {time.shape}")
        if not np.all(np.isfinite(time)) or np.any(np.diff(time) <= 0.0):
            raise InputError("trajectory.time: must be finite and strictly increasing")
        if not names or len(set(names)) != len(names) or not all(isinstance(n, str) and n for n in names):
            raise InputError(f"trajectory.joint_names: must be unique non-empty names, got {list(names)}")
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "joint_names", names)
        for field in ("positions", "velocities", "accelerations"):
            value = np.asarray(getattr(self, field), dtype=float)
            if value.shape != (time.size, len(names)):
                raise InputError(f"trajectory.{field}: must have shape {(time.size, len(names))}, got {value.shape}")
            if not np.all(np.isfinite(value)):
                raise InputError(f"trajectory.{field}: must be finite")
            object.__setattr__(self, field, value)

    @property
    def duration(self) -> float:
        """s from the first to the last sample."""
        return float(self.time[-1] - self.time[0])

    def columns(self, names: Iterable[str]) -> list[int]:
        """Indices of ``names`` in :attr:`joint_names` (ValueError if one is absent)."""
        return [self.joint_names.index(n) for n in names]
