"""Where points appear in Rerun's 3-D view: a plain look-at pinhole (z up, vertical field of view as Rerun's),
written independently of :mod:`cosim.io.rerun_framing`'s algebra, to check its cameras."""

from __future__ import annotations

import math

import numpy as np

from cosim.io.rerun_framing import RERUN_FOV_Y, VIEW_ASPECT


def image_coordinates(eye, target, points: np.ndarray, aspect: float = VIEW_ASPECT) -> np.ndarray:
    """(n, 2): where ``points`` ((n, 3) m) appear in a z-up perspective view from ``eye`` towards ``target`` of
    vertical field RERUN_FOV_Y and width / height ``aspect``, as fractions of the view's half-width (right +) and
    half-height (up +); AssertionError if a point is behind the eye."""
    eye, target = np.asarray(eye, dtype=float), np.asarray(target, dtype=float)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rel = np.asarray(points, dtype=float) - eye
    depth = rel @ forward
    assert np.all(depth > 0), "a point behind the eye"
    half_height = math.tan(0.5 * RERUN_FOV_Y)
    return np.column_stack([rel @ right / (depth * half_height * aspect), rel @ up / (depth * half_height)])
