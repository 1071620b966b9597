"""The memory check: its estimate against the arrays a solver really allocates, and the one-line refusals."""

from __future__ import annotations

import dataclasses

import pytest
import warp as wp

import cosim.fluid.memory
from cosim.cli.main import main
from cosim.errors import InputError
from cosim.bench.fluid_throughput import resting_block
from cosim.fluid.config import PressureSolver
from cosim.fluid.memory import allocation_failure_refused, liquid_bytes

# liquid_bytes leaves out the per-particle state (positions, velocities, densities, forces...), so it is a share of
# everything allocated. Measured on these blocks (and at 30k particles in 3-D): 2-D WCSPH 0.825 (the fewest pair
# slots a particle: 71 of 16 bytes), 2-D DFSPH 0.90, 3-D WCSPH 0.92 to 0.94, 3-D DFSPH 0.974, the scenes that can run
# out of memory. The bounds below leave a little room under those.
LOWER_BOUND_SHARE = {(2, PressureSolver.WCSPH): 0.8, (2, PressureSolver.DFSPH): 0.88, (3, PressureSolver.WCSPH): 0.9, (3, PressureSolver.DFSPH): 0.95}


def _allocated_bytes(root) -> int:
    """Bytes of every warp allocation reachable from ``root`` (owners only: a view counts through the array it
    views)."""
    seen, owners = set(), {}

    def visit(obj):
        if id(obj) in seen:
            return
        seen.add(id(obj))
        if isinstance(obj, wp.array):
            if obj.deleter is not None:
                owners[obj.ptr] = obj.capacity
            ref = getattr(obj, "_ref", None)
            if ref is not None:
                visit(ref)
        elif isinstance(obj, (list, tuple)):
            for item in obj:
                visit(item)
        elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
            for field in dataclasses.fields(obj):
                visit(getattr(obj, field.name))
        elif hasattr(obj, "__dict__") and type(obj).__module__.startswith("cosim."):
            for value in vars(obj).values():
                visit(value)

    visit(root)
    return sum(owners.values())


@pytest.mark.parametrize("dim,n", [(2, 1600), (3, 4000)])
@pytest.mark.parametrize("solver", [PressureSolver.WCSPH, PressureSolver.DFSPH])
def test_the_estimate_is_a_close_lower_bound_of_what_the_solver_allocates(dim, n, solver):
    fluid, _ = resting_block(n, dim, "cpu", 1, solver)
    estimate = liquid_bytes(fluid.config, fluid.n_particles, fluid.model.n_boundary)
    allocated = _allocated_bytes(fluid)
    assert LOWER_BOUND_SHARE[(dim, solver)] * allocated <= estimate <= allocated, (estimate, allocated, estimate / allocated)


def test_a_liquid_beyond_the_available_memory_is_refused_before_anything_is_allocated(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(cosim.fluid.memory, "available_bytes", lambda device: 50_000_000)  # 50 MB
    out = tmp_path / "run"
    assert main(["pour", "--dim", "3", "--no-log", "--quiet", "--duration", "0.01", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "need at least" in err[0] and "more than the 0.1 GB cpu can give" in err[0] and "fluid.particles_across" in err[0], err
    assert list(tmp_path.iterdir()) == []


def test_an_unknown_available_memory_is_no_check(monkeypatch):
    monkeypatch.setattr(cosim.fluid.memory, "available_bytes", lambda device: None)
    fluid, _ = resting_block(400, 2, "cpu", 1, PressureSolver.DFSPH)
    assert fluid.n_particles > 0


def test_warps_allocation_failure_is_the_same_one_line_error_and_other_errors_pass():
    with pytest.raises(InputError, match=r"^fluid: out of memory on cpu \(Failed to allocate 12 bytes on device 'cpu'\)"):
        with allocation_failure_refused("cpu"):
            raise RuntimeError("Failed to allocate 12 bytes on device 'cpu'")
    with pytest.raises(RuntimeError, match="something else"):
        with allocation_failure_refused("cpu"):
            raise RuntimeError("something else")
