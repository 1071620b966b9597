"""The PID design's specification (:class:`PidDesignSpec`), a setting of the pour controller's configuration.

Apart from the design (:mod:`controllers.pid`), so that reading a configuration loads no numerics (NumPy,
python-control): a scene file's settings are checked, and a bad one refused, before they load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from controllers.checks import check_range

if TYPE_CHECKING:
    import numpy as np

NOISE_FREQUENCY = 2.0 * math.pi * 40.0  # rad/s, PidDesignSpec.noise_frequency's default (its docstring)


@dataclass(frozen=True)
class PidDesignSpec:
    """Closed-loop target: poles of (s^2 + 2 zeta wn s + wn^2)(s + wn)^2 with wn = bandwidth_ratio * omega1, the
    bandwidth chosen for the loop with the actuation delay.

    damping: zeta of the complex pair, [0.3, 0.95] (1 would make a fourfold pole, which floating point cannot
      verify to better than 1e-4); not set: searched with the bandwidth over
      :data:`controllers.pid.DAMPING_RATIOS`.
    bandwidth_ratio: wn / omega1, [0.3, 3]; not set: searched over :data:`controllers.pid.BANDWIDTH_RATIOS`. The
      search keeps the pair whose sampled loop with the delay decays fastest within the margins.
    smoothing_bandwidth: rad/s, of the linear smoother between the PID and the arm
      (:class:`controllers.motion.CriticallyDampedSmoother`; its delay 2 / bandwidth). It keeps the arm's path
      smooth (no step-to-step jerk from the sampled PID) with a known transfer function that the design includes.
      [5, 1000]
    actuation_delay: s, from the smoothed tilt command to the vessel's tilt (the arms' joint generators and servos),
      rounded up to whole control periods in the design. [0, 0.5] The default is the coupled pour's, fitted from
      its series (docs/controller.md).
    min_gain_margin: dB. [0, 40]   min_phase_margin: deg. [0, 90]
    noise_frequency: rad/s, the lower edge of the band in which the measured slosh angle theta1 carries the liquid's
      own motion rather than its first slosh mode (the weakly compressible liquid's acoustic modes, the particles'
      passage), as the controller samples it. The PID reads theta1 through a second-order Butterworth low-pass
      (:func:`controllers.pid.measurement_filter`) at the geometric mean of omega1 and this frequency, and its design
      includes that filter. Default: 2 pi 40 Hz, measured with ``python -m cosim.bench.slosh_angle_spectrum`` on the
      default vessel and resolution (docs/controller.md). [20, 10000]; None (in code: a scene file that leaves it
      out gets the default): theta1 is read unfiltered.
    """

    damping: float | None = None
    bandwidth_ratio: float | None = None
    smoothing_bandwidth: float = 60.0
    actuation_delay: float = 0.04
    min_gain_margin: float = 6.0
    min_phase_margin: float = 45.0
    noise_frequency: float | None = NOISE_FREQUENCY

    def __post_init__(self) -> None:
        if self.damping is not None:
            check_range("pid.damping", self.damping, 0.3, 0.95)
        if self.bandwidth_ratio is not None:
            check_range("pid.bandwidth_ratio", self.bandwidth_ratio, 0.3, 3.0)
        check_range("pid.smoothing_bandwidth", self.smoothing_bandwidth, 5.0, 1000.0, "rad/s")
        check_range("pid.actuation_delay", self.actuation_delay, 0.0, 0.5, "s")
        check_range("pid.min_gain_margin", self.min_gain_margin, 0.0, 40.0, "dB")
        check_range("pid.min_phase_margin", self.min_phase_margin, 0.0, 90.0, "deg")
        if self.noise_frequency is not None:
            check_range("pid.noise_frequency", self.noise_frequency, 20.0, 10000.0, "rad/s")

    def target_poles(self, omega1: float, damping: float, bandwidth_ratio: float) -> np.ndarray:
        """The four target poles (rad/s) for a slosh frequency ``omega1`` (rad/s)."""
        import numpy as np

        wn = bandwidth_ratio * omega1
        wd = wn * math.sqrt(1.0 - damping**2)
        sr = -damping * wn
        return np.array([complex(sr, wd), complex(sr, -wd), -wn, -wn])
