"""The 3-D view's starting camera framed on a set of points of the scene: the nearest eye, looking from a given
direction at the middle of their bounding box, from which all the points lie within a given share of Rerun's
perspective view.

Rerun's 3-D view is a pinhole camera of vertical field of view :data:`RERUN_FOV_Y` whose horizontal field follows
the view's aspect ratio a (width / height): tan(fov_x / 2) = a tan(fov_y / 2). Seen from an eye at distance d from
the look target, along the unit vector b from the target to the eye, a point at offset r from the target lies
x = r . right across, y = r . up above and d - r . b in front of the eye; its image is at x / ((d - r . b) tan(fov_x /
2)) of the view's half-width and y / ((d - r . b) tan(fov_y / 2)) of its half-height. The point is inside ``fill`` of
both when

    d >= r . b + max(|x| / (fill tan(fov_x / 2)), |y| / (fill tan(fov_y / 2))),

and the camera takes the smallest d for which every point holds it: the points fill ``fill`` of the view's width or
height, whichever they reach first. The view is convex, so a solid whose corners are among the points (a box geom's
eight, :func:`geom_box_corners`) is then inside too.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from cosim.io.rerun_blueprint import Camera

# rad: the vertical field of view of Rerun's 3-D view (its eye's default, which a blueprint cannot change).
RERUN_FOV_Y = math.radians(55.0)
# Width / height of the 3-D view the framing assumes: the default blueprint's left column in a 16:10 window (0.9 in a
# 16:9 one); a wider view shows more beside the points, a narrower one would cut off the outermost.
VIEW_ASPECT = 0.85
# Share of the view's width or height (whichever binds) the points fill: the rest is a margin for the labels.
VIEW_FILL = 0.9
# World up (z), the view's up direction.
_UP = np.array([0.0, 0.0, 1.0])
# The eight corners of the cube [-1, 1]^3.
_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)


def geom_box_corners(model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray) -> np.ndarray:
    """(8 k, 3) m, world frame: the corners of each geom's bounding box (MuJoCo's ``geom_aabb``, in the geom's own
    frame) at ``data``'s pose; geoms: (k,) geom ids."""
    aabb = model.geom_aabb[geoms]  # (k, 6): centre and half-sizes
    local = aabb[:, None, :3] + _SIGNS[None] * aabb[:, None, 3:]
    rot = data.geom_xmat[geoms].reshape(-1, 3, 3)
    return (np.einsum("kij,kcj->kci", rot, local) + data.geom_xpos[geoms][:, None]).reshape(-1, 3)


def view_basis(toward_eye: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(right, up, back) unit vectors of a view whose eye lies along ``toward_eye`` (3,) from its target, z up;
    ValueError if ``toward_eye`` is vertical or zero."""
    back = np.asarray(toward_eye, dtype=float)
    right = np.cross(_UP, back)
    if np.linalg.norm(right) < 1e-9 * max(np.linalg.norm(back), 1.0):
        raise ValueError(f"toward_eye {back.tolist()}: must not be vertical")
    back = back / np.linalg.norm(back)
    right = right / np.linalg.norm(right)
    return right, np.cross(back, right), back


def frame_points(points: np.ndarray, toward_eye: np.ndarray, aspect: float = VIEW_ASPECT, fill: float = VIEW_FILL,
                 fov_y: float = RERUN_FOV_Y) -> Camera:
    """The camera looking at the middle of the bounding box of ``points`` ((n, 3) m, world frame) from the direction
    ``toward_eye`` (3,), at the nearest distance at which all the points lie within ``fill`` of a view of width /
    height ``aspect`` and vertical field of view ``fov_y`` (rad) (module docstring)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if not (len(points) and np.all(np.isfinite(points))):
        raise ValueError(f"points: need at least one, all finite (got {len(points)})")
    right, up, back = view_basis(toward_eye)
    target = 0.5 * (points.min(axis=0) + points.max(axis=0))
    offsets = points - target
    half_y = fill * math.tan(0.5 * fov_y)
    half_x = aspect * half_y
    needed = offsets @ back + np.maximum(np.abs(offsets @ right) / half_x, np.abs(offsets @ up) / half_y)
    eye = target + float(needed.max()) * back
    return Camera(tuple(float(v) for v in eye), tuple(float(v) for v in target))
