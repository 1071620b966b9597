"""The exp map of one axis-angle vector, the formula written out with numpy's own operations: the reference
``cosim.frames.rotation_from_vector`` (and the energy account's walls' work through it) is held to, bit for bit."""

import math

import numpy as np

from cosim.frames import vector_norm


def rodrigues(w: np.ndarray) -> np.ndarray:
    """(3, 3) rotation of the axis-angle vector ``w`` (3,) rad; the identity below 1e-12 rad."""
    angle = float(vector_norm(w))
    if angle < 1e-12:
        return np.eye(3)
    k = w / angle
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * kx + (1.0 - math.cos(angle)) * (kx @ kx)
