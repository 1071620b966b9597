"""Frame conversions: the one audited place where rotations change representation.

Conventions: world z up; quaternions are [w, x, y, z] (MuJoCo's order; warp's own quaternions are [x, y, z, w],
so warp kernels in this project take rotation matrices instead); rotation matrices map vessel-frame vectors to
world vectors (x_world = R @ x_local + p).
"""

from __future__ import annotations

import math

import numpy as np


def vector_norm(v) -> np.floating:
    """|v| of a vector: ``np.linalg.norm(v)``'s own steps (integers as floats, ``sqrt(x.dot(x))`` of the flattened
    array), so the same bits, without its argument dispatch, which dominates for the 3- and 4-vectors of the step
    loop."""
    x = np.asarray(v)
    if x.dtype.kind != "f":
        x = x.astype(float)
    x = x.ravel(order="K")
    return np.sqrt(x.dot(x))


def quat_wxyz_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrix (3, 3) of a unit quaternion [w, x, y, z] (normalised here). The entries are computed on plain
    floats (the exchange converts both vessels' quaternions every MuJoCo step, and on numpy scalars each operation
    costs a dispatch): the same double operations, so the same bits."""
    q = np.asarray(q, dtype=float).ravel(order="K")
    w, x, y, z = (q / np.sqrt(q.dot(q))).tolist()  # |q|: vector_norm's operations, without its call
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat_wxyz(r: np.ndarray) -> np.ndarray:
    """Unit quaternion [w, x, y, z] (w >= 0) of a rotation matrix (Shepperd's method)."""
    r = np.asarray(r, dtype=float)
    tr = np.trace(r)
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k])
        q = [0.0, 0.0, 0.0, 0.0]
        q[0] = (r[k, j] - r[j, k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (r[j, i] + r[i, j]) / s
        q[1 + k] = (r[k, i] + r[i, k]) / s
    q = np.array(q)
    return q if q[0] >= 0 else -q


def rotation_y(theta: float) -> np.ndarray:
    """R_y(theta): rotation about world +y by theta (rad); positive theta lowers a vessel's +x lip."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def tilt_about_y(r: np.ndarray) -> float:
    """The angle theta of the rotation about +y closest to ``r`` (rad): atan2(R[0, 2], R[2, 2])."""
    return math.atan2(r[0, 2], r[2, 2])


def rotation_vector(r: np.ndarray) -> np.ndarray:
    """Axis-angle vector (rad) of a rotation matrix: the log map, angle in [0, pi].

    On plain floats (the step loop calls it twice per MuJoCo step, and on nine numbers numpy's per-call overhead would
    outweigh the arithmetic), with the operations and their order of the equivalent array expressions: the same bits."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = np.asarray(r, dtype=float).tolist()
    angle = math.acos(min(max(0.5 * (r00 + r11 + r22 - 1.0), -1.0), 1.0))
    axis = (r21 - r12, r02 - r20, r10 - r01)
    if angle < 1e-9:
        return np.array([0.5 * a for a in axis])
    if math.pi - angle < 1e-6:
        # near pi: axis from the symmetric part
        m = 0.5 * (np.asarray(r, dtype=float) + np.eye(3))
        k = int(np.argmax(np.diag(m)))
        v = m[:, k] / math.sqrt(max(m[k, k], 1e-300))
        return angle * v / np.linalg.norm(v)
    scale = 2.0 * math.sin(angle)
    return np.array([angle * a / scale for a in axis])


_IDENTITY = np.eye(3)
_IDENTITY.flags.writeable = False


def rotation_from_vector(w: np.ndarray) -> np.ndarray:
    """Rotation matrix of an axis-angle vector (3,) (rad): the exp map (Rodrigues), the inverse of
    :func:`rotation_vector`: ``R = I + sin(a) K + (1 - cos(a)) K K`` with ``a = |w|`` and ``K`` the cross-product
    matrix of ``w / a`` (I below 1e-12 rad). The angle is sqrt(w . w) of the vector itself (:func:`vector_norm`'s
    operations without its dispatch), the axis is taken apart as plain floats and the identity is made once (the
    energy account calls this for every vessel every MuJoCo step): the same double operations, the same bits."""
    w = np.asarray(w, dtype=float)
    angle = math.sqrt(w.dot(w))
    if angle < 1e-12:
        return _IDENTITY.copy()
    k0, k1, k2 = (w / angle).tolist()
    kx = np.array([[0.0, -k2, k1], [k2, 0.0, -k0], [-k1, k0, 0.0]])
    return _IDENTITY + math.sin(angle) * kx + (1.0 - math.cos(angle)) * (kx @ kx)


def cross3(a, b) -> np.ndarray:
    """a x b of two 3-vectors (same arithmetic, and result, as ``np.cross``, without its dispatch cost, which
    dominates for a single pair in the step loop)."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


class Pose:
    """A rigid pose: ``position`` (3,) m and ``rotation`` (3, 3), mapping frame vectors to world vectors."""

    __slots__ = ("position", "rotation")

    def __init__(self, position=(0.0, 0.0, 0.0), rotation=None):
        self.position = np.array(position, dtype=float).reshape(3)
        self.rotation = np.eye(3) if rotation is None else np.array(rotation, dtype=float).reshape(3, 3)

    @classmethod
    def from_quat_wxyz(cls, position, quat) -> "Pose":
        pose = cls.__new__(cls)  # the new rotation matrix kept as it is (the constructor would copy it again)
        pose.position = np.array(position, dtype=float).reshape(3)
        pose.rotation = quat_wxyz_to_matrix(quat)
        return pose

    def transform(self, points_local: np.ndarray) -> np.ndarray:
        """World coordinates of points (n, 3) given in this frame."""
        return np.asarray(points_local) @ self.rotation.T + self.position

    def inverse_transform(self, points_world: np.ndarray) -> np.ndarray:
        """This frame's coordinates of world points (n, 3)."""
        return (np.asarray(points_world) - self.position) @ self.rotation

    def __repr__(self) -> str:
        return f"Pose(position={self.position.tolist()}, tilt_y={tilt_about_y(self.rotation):.4f} rad)"
