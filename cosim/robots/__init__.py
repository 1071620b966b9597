"""MuJoCo robot side: scene loading, vessel bodies, inverse kinematics, actuation, collision checks.

Conventions (shared by the whole project; every module here states the ones it relies on):

* World frame: z up, SI units, quaternions [w, x, y, z].
* Pour plane: the world x-z plane at y = 0. Both vessels' frames lie at y = 0 at home with their local y axes
  parallel to world y. The pour direction is world +x: the catcher sits at +x of the pourer's lip and lower.
* Vessel body frame in MuJoCo == :class:`cosim.vessel.VesselSpec` local frame: origin at the centre of the inner
  floor, +x toward the pour lip, +z up the vessel's axis. A pose read from MuJoCo is the fluid solver's vessel pose.
* Tilt theta is a rotation about world +y, ``R_y(theta) = [[c, 0, s], [0, 1, 0], [-s, 0, c]]``; positive theta lowers
  the +x lip (pours).
* Arms: ``pour_arm`` holds ``pourer``, ``catch_arm`` holds ``catcher``; joint names in a scene are
  ``<arm>/<joint>`` (``pour_arm/shoulder_pan``), the column stems of the trajectory CSV.

This package imports nothing at import time, so ``cosim.robots.planar`` (numpy only) can be used without MuJoCo.
"""
