"""Pouring controllers: pure numpy + python-control (no warp, no MuJoCo).

The slosh pendulum model and plant Gp (seed Eqs. 10-14, 17), the filtered-derivative PID compensator, the slosh
induction method (SIM) timeline, the constant-flow stage (CFS), the catcher's landing-point prediction
(Eqs. 6-7) and the pour state machine. Outputs are vessel targets; the robot side turns them into joint targets.
"""
