"""The kernel profile (cosim.bench.kernel_profile): its case syntax, and its per-operation timing on the CPU (its CUDA
tables need a GPU)."""

import re
from dataclasses import replace

import numpy as np
import pytest

from cosim.bench.kernel_profile import OperationTimer, parse_case, profile_case
from cosim.bench.fluid_throughput import resting_block
from cosim.fluid.config import DensityIteration, FluidConfig, PressureSolver


def test_cases_name_dimension_particles_solver_and_density_iteration():
    assert parse_case("3:1000000:wcsph") == (3, 1_000_000, PressureSolver.WCSPH, FluidConfig.density_iteration)
    assert parse_case("2:10000:dfsph:jacobi") == (2, 10_000, PressureSolver.DFSPH, DensityIteration.JACOBI)
    with pytest.raises(ValueError):
        parse_case("2:10000:sph")


def test_on_the_cpu_each_operation_is_timed_and_the_results_do_not_change():
    rows = profile_case(2, 400, PressureSolver.DFSPH, DensityIteration.GAUSS_SEIDEL, "cpu", 4, 50)
    table = [r for r in rows if r.startswith("| ") and not r.startswith("| operation")]
    names = [r.split(" | ")[0].lstrip("| ") for r in table]
    # the density solve's sweeps, the stage that records the pairs, the neighbour grid's sort
    assert {"gauss_seidel_density_sweep", "compute_density_factor", "integrate"} <= set(names)
    assert any(n.endswith(".sort") for n in names)
    wall, timed = (float(x) for x in re.search(r"wall ([\d.]+) ms .*?\), operations .*? ([\d.]+) ms", rows[2]).groups())
    assert 0.0 < timed <= wall  # the operations run inside the timed interval

    # the hook only wraps the calls: the same substeps give the same particles to the bit
    runs = []
    for hook in (None, OperationTimer()):
        fluid, interval = resting_block(400, 2, "cpu", 4, PressureSolver.DFSPH, graphs=False)
        fluid.operation_hook = hook
        fluid.advance(2 * interval)
        runs.append(fluid.positions())
    assert np.array_equal(*runs) and sum(hook.count.values()) > 0


def test_each_pair_layout_asked_for_is_profiled_with_the_rest_of_the_devices_layout(tmp_path):
    from cosim.bench.kernel_profile import main
    from cosim.fluid.device_layout import CPU_LAYOUT

    assert main(["--device", "cpu", "--cases", "2:400:dfsph:jacobi", "--steps", "4", "--pair-layouts", "rows", "columns", "packed", "--out", str(tmp_path)]) == 0
    headings = [line for line in (tmp_path / "kernel_profile.md").read_text().splitlines() if line.startswith("## ")]
    assert [h.rsplit(", ", 1)[1] for h in headings] == ["pair tables in rows", "pair tables in columns", "pair tables in packed"]

    # the solver is built with the layout asked for (slot-major tables on the CPU, the CPU's reductions kept)
    columns = replace(CPU_LAYOUT, pairs_by_column=True)
    fluid, _ = resting_block(400, 2, "cpu", 4, PressureSolver.DFSPH, graphs=False, layout=columns)
    assert fluid.layout == columns
