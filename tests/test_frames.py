"""cosim.frames: the scalar cross product and the vector norm the step loop uses in place of np.cross and
np.linalg.norm, and the stacked exp map the energy account takes its vessels' rotations from."""

import math

import numpy as np

from cosim.frames import cross3, rotation_from_vector, vector_norm
from tests.support.rodrigues import rodrigues


def test_cross3_is_np_cross_to_the_bit():
    # the coupling's wrench shift and the energy account switched to cross3 on the promise of identical results
    rng = np.random.default_rng(7)
    a = rng.normal(size=(1000, 3)) * 10.0 ** rng.integers(-8, 8, size=(1000, 1))
    b = rng.normal(size=(1000, 3)) * 10.0 ** rng.integers(-8, 8, size=(1000, 1))
    got = np.array([cross3(x, y) for x, y in zip(a, b)])
    np.testing.assert_array_equal(got, np.cross(a, b))
    assert cross3([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).tolist() == [0.0, 0.0, 1.0]


def test_vector_norm_is_np_linalg_norm_to_the_bit():
    # the IK, the quaternion conversion, the energy account and the solver's wall speed switched on that promise
    rng = np.random.default_rng(11)
    for size in (3, 4, 6):
        vectors = rng.normal(size=(300, size)) * 10.0 ** rng.integers(-8, 8, size=(300, 1))
        for v in vectors:
            got, expected = vector_norm(v), np.linalg.norm(v)
            assert type(got) is type(expected) and got.tobytes() == expected.tobytes()
    matrix = rng.normal(size=(6, 6))
    for v in (matrix[:, 2], matrix[1, ::2], matrix[2:4, 1:3], [3, 4], [1.0, 2.0, 2.0], np.array([0.1, 0.2, 0.3], dtype=np.float32)):
        got, expected = vector_norm(v), np.linalg.norm(v)  # strided, 2-D, integers, a list, float32
        assert type(got) is type(expected) and got.tobytes() == expected.tobytes()


def test_the_exp_map_is_the_formula_on_the_vector_alone_to_the_bit():
    # the energy account's rotations: the exp map on plain floats and a shared identity, on the promise of the
    # formula's bits (written out with numpy scalars in the reference)
    rng = np.random.default_rng(5)
    w = rng.normal(size=(400, 3)) * 10.0 ** rng.uniform(-14, 0.5, size=(400, 1))  # below 1e-12 rad to past pi
    w[::7] = 0.0
    w[3::11, :2] = 0.0  # about one axis only, as a 2-D vessel turns
    for vector in w:
        assert rotation_from_vector(vector).tobytes() == rodrigues(vector).tobytes()
    rest = rotation_from_vector(np.zeros(3))
    rest[0, 0] = 2.0  # a copy of the shared identity: the next one is the identity still
    assert rotation_from_vector(np.zeros(3)).tolist() == np.eye(3).tolist()
    angle = 0.3
    assert np.allclose(rotation_from_vector([0.0, angle, 0.0]), [[math.cos(angle), 0.0, math.sin(angle)], [0.0, 1.0, 0.0],
                                                                [-math.sin(angle), 0.0, math.cos(angle)]])
