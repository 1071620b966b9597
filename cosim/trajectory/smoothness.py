"""How smooth a sampled joint trajectory is: the two figures a robotics engineer reads chatter from.

Per joint of a :class:`cosim.trajectory.joint_trajectory.JointTrajectory` sampled uniformly at ``h`` s (the exported 500 Hz):

* ``acceleration_rms_above_hz``: the RMS (rad/s^2) of the part of the acceleration ``qdd`` above
  :data:`HIGH_FREQUENCY_HZ` (10 Hz, five times the pour's slosh frequency of about 2 Hz: motion a pour needs sits
  below it, vibration above). Computed with Parseval's theorem on the FFT of the sampled acceleration, after
  subtracting its end trend: the cubic that matches the acceleration and its slope (the jerk, from the first and last
  sample differences) at both ends of the record. The FFT treats the record as one period of a periodic signal; a
  jump or a kink where the end meets the start would leak into every bin (as 1/f and 1/f^2: 1 % of a 2 Hz motion's
  amplitude above 10 Hz on a 1.3 s record), after the subtraction only a jump of the curvature remains (1/f^3).
  The trend is a cubic over the whole record, slow motion by any measure (a pour starts and ends at rest, where it
  is zero). Then ``rms^2 = sum_{f_k > 10 Hz} w_k |X_k|^2 / N^2`` (``w_k`` = 2 for one-sided bins, 1 for the Nyquist
  bin), the mean square of the inverse transform of the bins above 10 Hz.
* ``jerk_sign_changes_per_s``: the jerk ``j_i = (qdd_{i+1} - qdd_i) / h`` (exact for the piecewise-polynomial
  motions the generators produce) changes sign this often per second. A change counts when the jerk goes from
  below ``-JERK_DEAD_BAND`` to above ``+JERK_DEAD_BAND`` or back (hysteresis: values inside the band keep the last
  sign), so that numerical noise around zero jerk on a joint at rest is not counted as motion.

:data:`JERK_DEAD_BAND` is 0.01 rad/s^3. Numerical noise in the jerk: the joint targets are inverse-kinematics
solutions converged to 1e-10 rad, streamed every 10 ms; differentiated three times over one target interval that is
1e-10 / 0.01^3 = 1e-4 rad/s^3, a hundredth of the band (float64 round-off of a difference of accelerations of a few
rad/s^2 over 2 ms is ~1e-12 rad/s^3). What the band hides: a jerk oscillation of amplitude 0.01 rad/s^3 at 5 Hz
(10 sign changes a second) moves the joint by 0.01 / (2 pi 5)^3 = 3e-7 rad, 0.3 micrometre at a metre's reach,
and it is 1e-4 of the UR10e-class jerk limit (100 rad/s^3, :mod:`cosim.trajectory.limits`).
"""

from __future__ import annotations

import numpy as np

from cosim.trajectory.joint_trajectory import JointTrajectory

HIGH_FREQUENCY_HZ = 10.0  # Hz, see the module docstring
JERK_DEAD_BAND = 0.01  # rad/s^3, see the module docstring


def acceleration_rms_above(acceleration: np.ndarray, sample_rate_hz: float, cutoff_hz: float = HIGH_FREQUENCY_HZ) -> np.ndarray:
    """(J,) rad/s^2: RMS of the content above ``cutoff_hz`` of ``acceleration`` (N, J), sampled at ``sample_rate_hz``
    (the module docstring's method)."""
    a = np.asarray(acceleration, dtype=float)
    n = a.shape[0]
    s = np.linspace(0.0, 1.0, n)[:, None]  # time over the record's length
    slope0, slope1 = (a[1] - a[0]) * (n - 1), (a[-1] - a[-2]) * (n - 1)  # d a / d s at the ends
    trend = (
        (2 * s**3 - 3 * s**2 + 1) * a[0] + (s**3 - 2 * s**2 + s) * slope0 + (3 * s**2 - 2 * s**3) * a[-1] + (s**3 - s**2) * slope1
    )
    detrended = a - trend
    spectrum = np.fft.rfft(detrended, axis=0)
    freq = np.fft.rfftfreq(n, 1.0 / sample_rate_hz)
    weight = np.where((freq == 0.0) | ((n % 2 == 0) & (freq == freq[-1])), 1.0, 2.0)
    high = freq > cutoff_hz
    power = np.sum(weight[high, None] * np.abs(spectrum[high]) ** 2, axis=0) / n**2
    return np.sqrt(power)


def jerk_sign_changes(jerk: np.ndarray, dead_band: float = JERK_DEAD_BAND) -> np.ndarray:
    """(J,) how many times each column of ``jerk`` (N, J) changes sign, with hysteresis ``dead_band`` (see the
    module docstring)."""
    j = np.asarray(jerk, dtype=float)
    sign = np.where(j > dead_band, 1, np.where(j < -dead_band, -1, 0))
    counts = []
    for column in sign.T:
        outside = column[column != 0]
        counts.append(int(np.count_nonzero(np.diff(outside))))
    return np.array(counts)


def trajectory_smoothness(trajectory: JointTrajectory) -> dict[str, dict[str, dict[str, float]]]:
    """Per arm, per joint (short name): ``acceleration_rms_above_10hz`` (rad/s^2) and ``jerk_sign_changes_per_s``;
    per arm also ``worst``: the largest of each over its joints."""
    t = trajectory.time
    h = float(t[1] - t[0])
    duration = float(t[-1] - t[0])
    rms = acceleration_rms_above(trajectory.accelerations, 1.0 / h)
    changes = jerk_sign_changes(np.diff(trajectory.accelerations, axis=0) / h) / duration
    report: dict[str, dict[str, dict[str, float]]] = {}
    for name, r, c in zip(trajectory.joint_names, rms.tolist(), changes.tolist()):
        arm, _, joint = name.partition("/")
        report.setdefault(arm, {})[joint] = {"acceleration_rms_above_10hz": r, "jerk_sign_changes_per_s": c}
    for joints in report.values():
        figures = list(joints.values())
        joints["worst"] = {key: max(f[key] for f in figures) for key in figures[0]}
    return report
