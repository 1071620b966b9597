"""Quintic Hermite interpolation of a sampled joint trajectory (positions, velocities, accelerations).

Between samples i and i+1 the position is the unique quintic matching position, velocity and acceleration at both
ends, so a trajectory sampled from any piecewise polynomial of degree <= 5 (e.g. ruckig's jerk-limited profiles,
which are cubic in position) is reproduced exactly, and the interpolant is C2 for any sampled trajectory.
Units follow the data (rad, rad/s, rad/s^2, s); outside ``[time[0], time[-1]]`` the end sample is held at rest.
"""

from __future__ import annotations

import numpy as np

from cosim.trajectory.joint_trajectory import JointTrajectory


class QuinticInterpolator:
    """Evaluate a :class:`JointTrajectory` at arbitrary times."""

    def __init__(self, trajectory: JointTrajectory) -> None:
        self.trajectory = trajectory

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q (J,), qd (J,), qdd (J,)) at time ``t`` s."""
        tr = self.trajectory
        if t <= tr.time[0]:
            return tr.positions[0].copy(), tr.velocities[0].copy(), tr.accelerations[0].copy()
        if t >= tr.time[-1]:
            zero = np.zeros(len(tr.joint_names))
            return tr.positions[-1].copy(), zero, zero.copy()
        i = int(np.searchsorted(tr.time, t, side="right")) - 1
        h = tr.time[i + 1] - tr.time[i]
        s = (t - tr.time[i]) / h
        p0, v0, a0 = tr.positions[i], tr.velocities[i] * h, tr.accelerations[i] * h * h
        p1, v1, a1 = tr.positions[i + 1], tr.velocities[i + 1] * h, tr.accelerations[i + 1] * h * h
        # Coefficients of p(s) = c0 + c1 s + ... + c5 s^5 on s in [0, 1] (derivatives scaled by h).
        c0, c1, c2 = p0, v0, 0.5 * a0
        c3 = 10 * (p1 - p0) - 6 * v0 - 4 * v1 - 1.5 * a0 + 0.5 * a1
        c4 = -15 * (p1 - p0) + 8 * v0 + 7 * v1 + 1.5 * a0 - a1
        c5 = 6 * (p1 - p0) - 3 * (v0 + v1) - 0.5 * (a0 - a1)
        q = c0 + s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * c5))))
        dq = c1 + s * (2 * c2 + s * (3 * c3 + s * (4 * c4 + s * 5 * c5)))
        ddq = 2 * c2 + s * (6 * c3 + s * (12 * c4 + s * 20 * c5))
        return q, dq / h, ddq / (h * h)
