"""Check a sampled joint trajectory against its arms' limits before it is written.

:func:`check_trajectory` verifies, for every joint of ``trajectory`` (samples ``t_i``, spacing ``h``):

1. finite values;
2. strictly increasing, uniform time: every ``t_{i+1} - t_i`` equals ``h`` within :data:`TIME_TOLERANCE`;
3. positions within ``[min_position, max_position]`` (slack :data:`POSITION_TOLERANCE`);
4. ``|qd| <= max_velocity``, ``|qdd| <= max_acceleration``;
5. jerk: ``|qdd_{i+1} - qdd_i| / h <= max_jerk`` (exact for any motion whose jerk is bounded, e.g. ruckig's
   piecewise-constant jerk);
6. continuity: ``|q_{i+1} - q_i| <= max_velocity h`` and ``|qd_{i+1} - qd_i| <= max_acceleration h``, the most the
   limits allow between two samples (mean value theorem): a jump the sampled velocities do not explain.

Bounds 4-6 get a relative slack :data:`LIMIT_RTOL` for floating-point round-off. The first violation (checks in the
order above, earliest time first) raises :class:`UnsafeTrajectoryError` with one line naming the arm, the joint, the
time, the value and the violated limit.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cosim.errors import SimulationError
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.limits import LIMIT_FIELDS, ArmLimits

# s: slack of the uniform-spacing check; sample times n / rate carry round-off of ~1e-16 t.
TIME_TOLERANCE = 1e-9
# rad: slack of the joint-range check (round-off of positions of order 10 rad).
POSITION_TOLERANCE = 1e-9
# Relative slack of the velocity, acceleration, jerk and continuity bounds, for round-off: ruckig holds its limits up
# to round-off (of order 1e-15 relative, largest on the jerk differenced from accelerations), far below this slack.
LIMIT_RTOL = 1e-9


class UnsafeTrajectoryError(SimulationError):
    """A generated trajectory breaks a limit; the message is one line naming arm, joint, time and limit."""


def _joint_limits(trajectory: JointTrajectory, limits: Sequence[ArmLimits]) -> dict[str, np.ndarray]:
    by_name = {j.name: j for arm in limits for j in arm.joints}
    missing = [n for n in trajectory.joint_names if n not in by_name]
    if missing:
        raise ValueError(f"check_trajectory: no limits for joint(s) {', '.join(missing)}")
    return {field: np.array([getattr(by_name[n], field) for n in trajectory.joint_names]) for field in LIMIT_FIELDS}


def _error(name: str, t: float, problem: str) -> UnsafeTrajectoryError:
    arm, _, joint = name.partition("/")
    return UnsafeTrajectoryError(f"unsafe trajectory: arm {arm}, joint {joint}, t={t:.4f} s: {problem}")


def _first(mask: np.ndarray) -> tuple[int, int] | None:
    """(sample, joint) of the earliest True entry of ``mask`` (samples x joints; lowest joint index on ties), or None."""
    rows, cols = np.nonzero(mask)
    if rows.size == 0:
        return None
    return int(rows[0]), int(cols[0])  # np.nonzero lists entries in row-major order


def check_trajectory(trajectory: JointTrajectory, limits: Sequence[ArmLimits]) -> None:
    """Raise :class:`UnsafeTrajectoryError` unless ``trajectory`` holds every limit (see the module docstring)."""
    lim = _joint_limits(trajectory, limits)
    names, t = trajectory.joint_names, trajectory.time
    q, qd, qdd = trajectory.positions, trajectory.velocities, trajectory.accelerations

    for field, values in (("position", q), ("velocity", qd), ("acceleration", qdd)):
        bad = _first(~np.isfinite(values))
        if bad is not None:
            raise _error(names[bad[1]], t[bad[0]], f"{field} is not finite")
    if not np.all(np.isfinite(t)):
        raise UnsafeTrajectoryError("unsafe trajectory: time is not finite")
    steps = np.diff(t)
    h = float(steps[0])
    if h <= 0.0 or np.any(np.abs(steps - h) > TIME_TOLERANCE):
        i = int(np.argmax(np.abs(steps - h) > TIME_TOLERANCE)) if h > 0.0 else 0
        raise UnsafeTrajectoryError(
            f"unsafe trajectory: time is not strictly increasing and uniform: step {steps[i]:.9g} s at t={t[i]:.4f} s, "
            f"the first step is {h:.9g} s"
        )

    for mask, relation, field in (
        (q < lim["min_position"] - POSITION_TOLERANCE, "below", "min_position"),
        (q > lim["max_position"] + POSITION_TOLERANCE, "above", "max_position"),
    ):
        bad = _first(mask)
        if bad is not None:
            i, j = bad
            raise _error(names[j], t[i], f"position {q[i, j]:.6g} rad {relation} {field} {lim[field][j]:.6g} rad")

    bounded = (
        (qd, "velocity", "max_velocity", lim["max_velocity"], "rad/s"),
        (qdd, "acceleration", "max_acceleration", lim["max_acceleration"], "rad/s^2"),
        (np.diff(qdd, axis=0) / h, "jerk (acceleration difference / h)", "max_jerk", lim["max_jerk"], "rad/s^3"),
        (np.diff(q, axis=0), "position step", "max_velocity * h", lim["max_velocity"] * h, "rad"),
        (np.diff(qd, axis=0), "velocity step", "max_acceleration * h", lim["max_acceleration"] * h, "rad/s"),
    )
    for values, what, field, limit, unit in bounded:
        bad = _first(np.abs(values) > limit * (1.0 + LIMIT_RTOL))
        if bad is not None:
            i, j = bad
            raise _error(names[j], t[i], f"|{what}| {abs(values[i, j]):.6g} {unit} above {field} {limit[j]:.6g} {unit}")


def check_torques(trajectory: JointTrajectory, torques: np.ndarray, limits: Sequence[ArmLimits]) -> None:
    """Raise :class:`UnsafeTrajectoryError` (one line: arm, joint, time, torque, rating) unless every joint's
    required torque ``torques`` (samples x joints, N m, :func:`cosim.trajectory.torques.required_torques`) stays
    within its ``rated_torque`` (relative slack :data:`LIMIT_RTOL`)."""
    rated = _joint_limits(trajectory, limits)["rated_torque"]
    bad = _first(np.abs(torques) > rated * (1.0 + LIMIT_RTOL))
    if bad is not None:
        i, j = bad
        name = trajectory.joint_names[j]
        raise _error(name, trajectory.time[i], f"|required torque| {abs(torques[i, j]):.6g} N m above rated_torque {rated[j]:.6g} N m")
