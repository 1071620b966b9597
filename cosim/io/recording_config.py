"""What a pour's Rerun recording holds (its own module: a scene names it without needing rerun-sdk)."""

from __future__ import annotations

from dataclasses import dataclass

from declared_settings.setting import check_settings, documented, setting

RECORDING = "recording"


@documented
@dataclass(frozen=True)
class RecordingConfig:
    """What goes into the recording."""

    particle_stride: int = setting(1, RECORDING, "Log every k-th liquid particle (by particle index, so the same "
                                   "particles are shown in every frame).", "", 1, 1000)
    particle_rate_hz: float = setting(30.0, RECORDING, "At most how often (per simulated second) body poses, tool "
                                      "frames, particles, the liquid's force and the landing points are logged; "
                                      "scalars are logged at every call.", "Hz", 0.0, 1000.0, lo_open=True)
    speed_color_max: float = setting(2.0, RECORDING, "Particle speed at the top of the colour map (faster particles "
                                     "share its top colour).", "m/s", 0.0, 100.0, lo_open=True)

    def __post_init__(self) -> None:
        check_settings(self, "recording")
