"""The PID design's specification (:class:`PidDesignSpec`), a setting of the pour controller's configuration.

Apart from the design (:mod:`controllers.pid`), so that reading a configuration loads no numerics (NumPy,
python-control): a scene file's settings are checked, and a bad one refused, before they load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from declared_settings.setting import check_settings, documented, setting

if TYPE_CHECKING:
    import numpy as np

PID = "PID design"


@documented
@dataclass(frozen=True)
class PidDesignSpec:
    """Closed-loop target: poles of (s^2 + 2 zeta wn s + wn^2)(s + wn)^2 with wn = bandwidth_ratio * omega1, the
    bandwidth chosen for the loop with the actuation delay, the smoother and the measurement filter
    (:func:`controllers.pid.design_filtered_pid`)."""

    damping: float | None = setting(
        None, PID, "zeta of the target's complex pole pair (at most 0.95: 1 would make a fourfold pole, which floating "
        "point cannot verify to better than 1e-4).", "", 0.3, 0.95,
        none_means="searched with the bandwidth over controllers.pid.DAMPING_RATIOS")
    bandwidth_ratio: float | None = setting(
        None, PID, "wn / omega1 of the target poles.", "", 0.3, 3.0,
        none_means="searched over controllers.pid.BANDWIDTH_RATIOS; the search keeps the pair whose sampled loop with "
        "the delay decays fastest within the margins")
    smoothing_bandwidth: float = setting(
        60.0, PID, "Bandwidth of the linear smoother between the PID and the arm "
        "(controllers.motion.CriticallyDampedSmoother; its delay 2 / bandwidth). It keeps the arm's path smooth (no "
        "step-to-step jerk from the sampled PID) with a known transfer function that the design includes.", "rad/s",
        5.0, 1000.0)
    actuation_delay: float = setting(
        0.04, PID, "Delay from the smoothed tilt command to the vessel's tilt (the arms' joint generators and servos), "
        "rounded up to whole control periods in the design. The default is the coupled pour's, fitted from its series "
        "(docs/controller.md).", "s", 0.0, 0.5)
    min_gain_margin: float = setting(6.0, PID, "Least gain margin of the sampled loop with the delay.", "dB", 0.0, 40.0)
    min_phase_margin: float = setting(45.0, PID, "Least phase margin of the sampled loop with the delay.", "deg",
                                      0.0, 90.0)
    noise_frequency: float | None = setting(
        2.0 * math.pi * 40.0, PID, "Lower edge of the band in which the measured slosh angle theta1 carries the "
        "liquid's own motion rather than its first slosh mode (the weakly compressible liquid's acoustic modes, the "
        "particles' passage), as the controller samples it. The PID reads theta1 through a second-order Butterworth "
        "low-pass (controllers.pid.measurement_filter) at the geometric mean of omega1 and this frequency, and its "
        "design includes that filter. The default, 2 pi 40 Hz, is the band's edge for the default vessel and "
        "resolution (docs/controller.md).", "rad/s", 20.0, 10000.0,
        none_means="theta1 read unfiltered (None in code; a scene file that leaves it out gets the default)")

    def __post_init__(self) -> None:
        check_settings(self, "pid")

    def target_poles(self, omega1: float, damping: float, bandwidth_ratio: float) -> np.ndarray:
        """The four target poles (rad/s) for a slosh frequency ``omega1`` (rad/s)."""
        import numpy as np

        wn = bandwidth_ratio * omega1
        wd = wn * math.sqrt(1.0 - damping**2)
        sr = -damping * wn
        return np.array([complex(sr, wd), complex(sr, -wd), -wn, -wn])
