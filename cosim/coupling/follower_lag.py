"""How late the pourer follows the controller's tilt command on a ramp: the coupling's chain, by construction.

The partial pour's stop predicts the after-flow (:func:`controllers.cfs.after_flow_volume`), which counts the outflow
while the vessel still follows the commands given before the stop: the follower's lag. In the coupled pour
(:mod:`cosim.coupling.loop`) a CFS tilt command reaches the vessel through four linear stages, each of which follows a
ramp at a constant lag once its start has died away:

1. the pose filter's tracking law (:class:`cosim.coupling.tracking_filter.TrackingFilter`): ``K1 / K0``, its gains
   placed from :data:`cosim.coupling.pose_filter.TRACKING_BANDWIDTH` and the control period (about 3 / w);
2. the smoothing stages (:class:`cosim.coupling.pose_filter.PoseSmoother`): ``(1 - a) / a`` periods each;
3. the joint generators' B-spline through the target stream: knot states ``STREAM_DELAY_PERIODS`` periods behind the
   stream (:mod:`cosim.trajectory.generator`), of which one is the period ahead that the pose filter's poses are for;
4. the servos: ``kp (q_d - q) + kv (qd_d - qdot)`` with the desired velocity fed forward and gravity compensated from
   the model (:mod:`cosim.robots.scene`), so with no other load the error of a ramp obeys
   ``M e'' + kv e' + kp e = 0`` and dies out: no lag. (A PD servo without the velocity feedforward would add
   ``kv / kp``.)

Their sum is the lag of the arm following a ramp with no liquid. The liquid's load on an arm that compensates a static
payload deflects the vessel from its command by a slowly changing offset; it is not a delay, and a pure delay fitted
to the commanded and measured tilt reads it as one (offset / tilt rate). On a ramp an offset and a delay cannot be
told apart at all, so the coupling hands the controller this lag (``PourConfig.follower_lag``) rather than have it fit
one; ``tests/test_coupling_follower_lag.py`` checks it against the arm driven along a ramp without liquid.
"""

from __future__ import annotations

import numpy as np

from controllers.motion import CriticallyDampedSmoother
from cosim.coupling.pose_filter import SMOOTHING_BANDWIDTH, SMOOTHING_STAGES, TRACKING_BANDWIDTH
from cosim.coupling.tracking_filter import TrackingFilter
from cosim.trajectory.generator import STREAM_DELAY_PERIODS


def follower_lag(control_period: float) -> float:
    """s: how far the pourer's tilt follows a ramp of the controller's tilt command behind it, at the control period
    ``control_period`` (s), with no liquid (the module docstring): tracking law + smoothing + spline, the servos
    adding nothing."""
    unit = np.ones(1)  # the tracking law's lag depends on its bandwidth and period alone, not on the limits
    tracking = TrackingFilter(unit, unit, unit, TRACKING_BANDWIDTH, control_period).lag
    smoothing = CriticallyDampedSmoother(SMOOTHING_BANDWIDTH, control_period, SMOOTHING_STAGES).delay
    spline = (STREAM_DELAY_PERIODS - 1) * control_period
    return tracking + smoothing + spline
