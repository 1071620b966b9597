"""The kernel profile's case syntax (cosim.bench.kernel_profile; its CUDA tables need a GPU)."""

import pytest

from cosim.bench.kernel_profile import parse_case
from cosim.fluid.config import DensityIteration, FluidConfig, PressureSolver


def test_cases_name_dimension_particles_solver_and_density_iteration():
    assert parse_case("3:1000000:wcsph") == (3, 1_000_000, PressureSolver.WCSPH, FluidConfig.density_iteration)
    assert parse_case("2:10000:dfsph:jacobi") == (2, 10_000, PressureSolver.DFSPH, DensityIteration.JACOBI)
    with pytest.raises(ValueError):
        parse_case("2:10000:sph")
