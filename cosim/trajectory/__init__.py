"""Jerk-limited joint trajectories for real arms: the trajectory type and its files, limits, online generation,
sampling, checks, smoothness, scripted motions and their replay on the MuJoCo arms.

Modules: :mod:`~cosim.trajectory.joint_trajectory` (the sampled trajectory), its file formats
:mod:`~cosim.trajectory.csv_file`, :mod:`~cosim.trajectory.json_file` and :mod:`~cosim.trajectory.mcap_file` (the
last two from ROS ``JointTrajectoryPoint`` fields, :mod:`~cosim.trajectory.ros_points`),
:mod:`~cosim.trajectory.limits` (per-joint limits and their defaults), :mod:`~cosim.trajectory.generator` (one
online generator per arm, fed IK targets by the coupling: a B-spline through them, ruckig to catch up),
:mod:`~cosim.trajectory.recorder` (fixed-rate sampling), :mod:`~cosim.trajectory.checks` (every limit verified
before writing), :mod:`~cosim.trajectory.smoothness` (acceleration content above 10 Hz, jerk sign changes),
:mod:`~cosim.trajectory.export` (checked CSV + JSON + MCAP), :mod:`~cosim.trajectory.pour_motion` (a quintic-timed
pour by IK), :mod:`~cosim.trajectory.scripted` (scripted vessel targets -> checked trajectory),
:mod:`~cosim.trajectory.deviation` (lip path deviation), :mod:`~cosim.trajectory.torques` (joint torques of a
trajectory) and :mod:`~cosim.trajectory.replay` (servo tracking of a trajectory, with
:mod:`~cosim.trajectory.interpolation` between its samples).
Units: rad, rad/s, rad/s^2, rad/s^3, s.
"""
