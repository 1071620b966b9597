"""What a pour's Rerun recording holds (its own module: a scene names it without needing rerun-sdk)."""

from __future__ import annotations

from dataclasses import dataclass

from cosim.checks import check_int, check_positive, check_range


@dataclass(frozen=True)
class RecordingConfig:
    """What goes into the recording.

    particle_stride: log every k-th liquid particle (by particle index, so the same particles are shown in every
        frame). [1, 1000]
    particle_rate_hz: Hz of simulated time, at most how often body poses, tool frames, particles, the liquid's force
        and the landing points are logged; scalars are logged at every call. (0, 1000]
    speed_color_max: m/s, particle speed at the top of the colour map (faster particles share its top colour).
        (0, 100]
    """

    particle_stride: int = 1
    particle_rate_hz: float = 50.0
    speed_color_max: float = 2.0

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "particle_stride", check_int("recording.particle_stride", self.particle_stride, 1, 1000))
        s(self, "particle_rate_hz", check_range("recording.particle_rate_hz", self.particle_rate_hz, 0.0, 1000.0, "Hz", lo_open=True))
        s(self, "speed_color_max", check_positive("recording.speed_color_max", self.speed_color_max, "m/s", 100.0))
