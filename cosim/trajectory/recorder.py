"""Sample the motion of the arms' trajectory generators at a fixed rate into one :class:`JointTrajectory`.

Samples lie at ``t_n = t_0 + n / sample_rate_hz`` (s), ``t_0`` the generators' time when the recorder is made; each is
the generator's exact motion at that time (:meth:`TrajectoryGenerator.state_at`), so any rate is supported exactly,
not only divisors of the cycle rate. Columns: the generators' joints in the order given (pass them in
:class:`cosim.robots.scene_config.ArmRole` order for the trajectory files' column order), base to tip.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cosim.trajectory.generator import TIME_EPSILON, TrajectoryGenerator
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.limits import ArmLimits
from cosim.trajectory.sampling import DEFAULT_SAMPLE_RATE_HZ, SAMPLE_RATE


class TrajectoryRecorder:
    """Records ``generators`` (all with the same cycle time and clock) at ``sample_rate_hz`` (Hz, in
    :data:`cosim.trajectory.sampling.SAMPLE_RATE`'s range).

    Call :meth:`record` after every :meth:`TrajectoryGenerator.step` of all generators; :meth:`trajectory` returns
    what was recorded so far.
    """

    def __init__(self, generators: Sequence[TrajectoryGenerator], sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ) -> None:
        self.sample_rate_hz = SAMPLE_RATE.check("trajectory.sample_rate_hz", sample_rate_hz)
        self.generators = tuple(generators)
        if not self.generators:
            raise ValueError("TrajectoryRecorder needs at least one generator")
        first = self.generators[0]
        for g in self.generators[1:]:
            if g.settings.cycle_time != first.settings.cycle_time or g.time != first.time:
                raise ValueError("TrajectoryRecorder: the generators must share their cycle time and clock")
        self.joint_names = tuple(name for g in self.generators for name in g.limits.joint_names)
        self._t0 = first.time
        self._times: list[float] = []
        self._rows: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self.record()

    @property
    def limits(self) -> tuple[ArmLimits, ...]:
        """The generators' limits, in column order."""
        return tuple(g.limits for g in self.generators)

    def _sample_time(self, n: int) -> float:
        return self._t0 + n / self.sample_rate_hz

    def record(self) -> None:
        """Take every sample due up to the generators' current time (inside their last step)."""
        times = {g.time for g in self.generators}
        if len(times) > 1:
            raise ValueError("TrajectoryRecorder.record: the generators are at different times; step them all first")
        now = times.pop()
        t = self._sample_time(len(self._times))
        while t <= now + TIME_EPSILON:
            # per quantity (q, qd, qdd) the generators' arrays joined, in generator order
            self._rows.append(tuple([np.concatenate(column) for column in zip(*[g.state_at(t) for g in self.generators])]))  # type: ignore[arg-type]
            self._times.append(t)
            t = self._sample_time(len(self._times))

    def trajectory(self) -> JointTrajectory:
        """The samples so far (at least two are needed)."""
        return JointTrajectory(
            time=np.array(self._times),
            joint_names=self.joint_names,
            positions=np.array([r[0] for r in self._rows]),
            velocities=np.array([r[1] for r in self._rows]),
            accelerations=np.array([r[2] for r in self._rows]),
        )
