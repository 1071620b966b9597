"""Jerk-limited joint trajectories for real arms: limits, online generation, sampling, checks, smoothness, export.

Modules: :mod:`~cosim.trajectory.limits` (per-joint limits and their defaults), :mod:`~cosim.trajectory.generator`
(one online generator per arm, fed IK targets by the coupling: a B-spline through them, ruckig to catch up), :mod:`~cosim.trajectory.recorder` (fixed-rate
sampling into a :class:`~cosim.io.trajectory_csv.JointTrajectory`), :mod:`~cosim.trajectory.checks` (every limit
verified before writing), :mod:`~cosim.trajectory.export` (checked CSV + JSON), :mod:`~cosim.trajectory.scripted`
(scripted vessel targets -> checked trajectory), :mod:`~cosim.trajectory.deviation` (lip path deviation) and
:mod:`~cosim.trajectory.smoothness` (acceleration content above 10 Hz, jerk sign changes).
Units: rad, rad/s, rad/s^2, rad/s^3, s.
"""
