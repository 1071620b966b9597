"""The throughput benchmark's neighbour count (cosim.bench.fluid_throughput.mean_neighbours), which turns
particle-steps per second into pair interactions per second."""

import numpy as np
import pytest

from cosim.bench.fluid_throughput import mean_neighbours


def test_mean_neighbours_counts_the_other_points_strictly_inside_the_radius():
    lattice = np.stack(np.meshgrid(*[np.arange(3.0)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    # radius just over the spacing: each lattice edge joins two points, 54 edges in a 3 x 3 x 3 block
    assert mean_neighbours(lattice, 1.01) == 2 * 54 / 27
    # a point at exactly the radius is left out, as the neighbour walk leaves it out (r^2 < support^2)
    assert mean_neighbours(lattice, 1.0) == 0.0
    # radius 1.5: the 6 face and 12 edge neighbours of the centre point are inside, the 8 corners (sqrt 3) are not
    squared = ((lattice[:, None, :] - lattice[None, :, :]) ** 2).sum(axis=-1)
    brute_force = ((squared < 1.5**2).sum() - len(lattice)) / len(lattice)
    assert mean_neighbours(lattice, 1.5) == pytest.approx(brute_force, rel=1e-12)
    assert mean_neighbours(np.array([[0.0, 0.0], [0.3, 0.4]]), 0.6) == 1.0
