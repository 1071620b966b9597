"""Planar vessel targets in the pour plane (numpy only, no MuJoCo).

Conventions: world z up, SI units, quaternions [w, x, y, z]. The pour plane is the world x-z plane at y = 0.
Tilt theta is a rotation about world +y, ``R_y(theta) = [[c, 0, s], [0, 1, 0], [-s, 0, c]]``; positive theta lowers
the +x lip (pours).

A controller's vessel target is a :class:`PlanarPose` relative to the vessel's HOME pose ``(p_home, R_home)``:
world position ``p_home + (dx, 0, dz)``, world orientation ``R_y(theta) @ R_home``. :func:`tilt_about_pivot` builds
such a target from "tilt by an angle about the line through a point p of the vessel (given in the vessel frame),
parallel to world y, plus a translation"; Camporredondo et al. (2019) tilt about the bottom middle ``(0, 0, 0)``
during SIM and about the lip (``VesselSpec.lip_local``) during CFS.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cosim.checks import check_number, check_vector
from cosim.frames import matrix_to_quat_wxyz, quat_wxyz_to_matrix, rotation_y


@dataclass(frozen=True)
class PlanarPose:
    """Vessel pose relative to its home pose, in the pour plane.

    dx: m, world x offset of the vessel frame origin from home.
    dz: m, world z offset of the vessel frame origin from home.
    theta: rad, tilt about world +y applied on top of the home orientation (positive pours).
    """

    dx: float = 0.0
    dz: float = 0.0
    theta: float = 0.0

    def __post_init__(self) -> None:
        for name in ("dx", "dz", "theta"):
            object.__setattr__(self, name, check_number(f"planar_pose.{name}", getattr(self, name)))


def planar_to_world(home_pos: np.ndarray, home_quat: np.ndarray, pose: PlanarPose) -> tuple[np.ndarray, np.ndarray]:
    """World pose of the vessel frame for ``pose`` relative to home.

    Returns ``(pos (3,), quat (4,) [w, x, y, z])``: ``pos = home_pos + (dx, 0, dz)``,
    ``R = R_y(theta) @ R_home``.
    """
    pos = np.asarray(home_pos, dtype=float) + np.array([pose.dx, 0.0, pose.dz])
    rot = rotation_y(pose.theta) @ quat_wxyz_to_matrix(home_quat)
    return pos, matrix_to_quat_wxyz(rot)


def tilt_about_pivot(
    home_quat: np.ndarray,
    pivot_local: np.ndarray,
    dtheta: float,
    translation: tuple[float, float] = (0.0, 0.0),
    current: PlanarPose = PlanarPose(),
) -> PlanarPose:
    """Target after tilting by ``dtheta`` (rad) about a pivot line parallel to world y, plus a translation.

    pivot_local: (3,) m, a point on the pivot line in the vessel frame at the ``current`` pose (e.g. ``(0, 0, 0)``,
        the bottom middle, or ``VesselSpec.lip_local``); the line runs through it parallel to world y.
    translation: (dx, dz) m added in world x and z after the tilt.
    current: the pose (relative to home) the tilt starts from; the default is home.
    home_quat: (4,) [w, x, y, z], the vessel's home orientation.

    With the current vessel frame ``(p_c, R_c)``, pivot ``c = p_c + R_c p``: the new origin is
    ``c + R_y(dtheta) (p_c - c) + (tx, 0, tz)`` and the new tilt ``current.theta + dtheta``. The pivot point itself
    does not move (apart from the translation).
    """
    pivot = np.asarray(check_vector("tilt.pivot_local", tuple(np.asarray(pivot_local, dtype=float)), 3))
    tx, tz = check_vector("tilt.translation", tuple(translation), 2)
    dtheta = check_number("tilt.dtheta", dtheta)
    r_current = rotation_y(current.theta) @ quat_wxyz_to_matrix(home_quat)
    offset = r_current @ pivot  # pivot minus current origin, world frame
    moved = offset - rotation_y(dtheta) @ offset  # displacement of the origin caused by the tilt about the pivot
    return PlanarPose(current.dx + moved[0] + tx, current.dz + moved[2] + tz, current.theta + dtheta)
