"""Jerk-limited joint trajectories for real arms: limits, online ruckig generation, sampling, checks, export.

Modules: :mod:`~cosim.trajectory.limits` (per-joint limits and their defaults), :mod:`~cosim.trajectory.generator`
(one online ruckig generator per arm, fed IK targets by the coupling), :mod:`~cosim.trajectory.recorder` (fixed-rate
sampling into a :class:`~cosim.io.trajectory_csv.JointTrajectory`), :mod:`~cosim.trajectory.checks` (every limit
verified before writing), :mod:`~cosim.trajectory.export` (checked CSV + JSON), :mod:`~cosim.trajectory.scripted`
(scripted vessel targets -> checked trajectory) and :mod:`~cosim.trajectory.deviation` (lip path deviation).
Units: rad, rad/s, rad/s^2, rad/s^3, s.
"""
