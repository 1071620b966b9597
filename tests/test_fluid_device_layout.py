"""The CUDA layouts of the pair tables, the wrench reduction and the diagnostics rows (cosim.fluid.device_layout),
run on the CPU: the same particle state bit for bit as the CPU layout, the sums the same to float32 rounding."""

import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from cosim.fluid import solver as solver_module
from cosim.fluid.config import FluidConfig
from cosim.fluid.device_layout import CPU_LAYOUT, CUDA_LAYOUT, CUDA_SWEEP_LAYOUT, REDUCTION_ITEMS, WRENCH_CHUNKS, layout_for, reduction_levels
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose, rotation_y
from cosim.vessel import VesselSpec

# float32 sums of the same terms in another order: a few ulps of the largest partial sum
SUM_ORDER_RTOL = 1e-5


@pytest.mark.parametrize("interleaved", [False, True])
@pytest.mark.parametrize("n", [1, 63, 64, 65, 4095, 4097, 300_001])
def test_reduction_levels_sum_every_item_once(n, interleaved):
    items = np.arange(n)
    for level in reduction_levels(n, interleaved):
        assert len(items) == level.length
        seen = []
        for c in range(level.chunks):
            seen += [c * level.first_stride + j * level.item_stride for j in range(level.items) if c * level.first_stride + j * level.item_stride < level.length]
        assert sorted(seen) == list(range(level.length))
        items = np.arange(level.chunks)
    assert len(items) <= (REDUCTION_ITEMS if interleaved else WRENCH_CHUNKS)


def _shaken_tank(dim: int, solver: str, layout, **numerics):
    tank = VesselSpec(name="tank", inner_width=0.1, inner_depth=0.1, inner_height=0.15)
    cfg = FluidConfig(dim=dim, spacing=0.1 / (20 if dim == 2 else 8), pressure_solver=solver, max_expected_speed=1.5,
                      domain_min=(-0.15, -0.15, -0.05), domain_max=(0.15, 0.15, 0.25), **numerics)
    fluid = FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, 0.06, cfg), layout=layout)
    for k in range(1, 6):
        fluid.set_vessel_poses([Pose((0.005 * math.sin(k), 0.0, 0.0), rotation_y(0.05 * k))])
        fluid.advance(0.004)
    return fluid


def _pair_layout(fluid):
    """How the solver's pair tables are laid out: DFSPH's slots (step, stride: columns, rows or packed), WCSPH's
    table strides."""
    sc = fluid.step.scratch
    slots = getattr(sc, "pair_slots", None)
    return (slots.step, slots.stride) if slots is not None else sc.pairs.index.strides


@pytest.mark.parametrize("layout", [CUDA_LAYOUT, CUDA_SWEEP_LAYOUT], ids=["cuda", "cuda-sweeps"])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("solver", ["wcsph", "dfsph"])
def test_the_cuda_layouts_give_the_cpu_layouts_state(dim, solver, layout):
    ref = _shaken_tank(dim, solver, CPU_LAYOUT)
    cuda = _shaken_tank(dim, solver, layout)
    differ = layout.pairs_by_column or (solver == "dfsph" and layout.pairs_packed != CPU_LAYOUT.pairs_packed)
    assert (_pair_layout(cuda) != _pair_layout(ref)) == differ  # the layouts differ in memory...
    assert np.array_equal(ref.positions(), cuda.positions())  # ...not in the particles
    assert np.array_equal(ref.state.v.numpy(), cuda.state.v.numpy())
    wrench_scale = np.abs(ref.vessel_wrenches()).max()
    assert np.abs(ref.vessel_wrenches() - cuda.vessel_wrenches()).max() <= SUM_ORDER_RTOL * wrench_scale
    a, b = ref.history(), cuda.history()
    assert len(a["dt"]) > 5 and a.keys() == b.keys()
    for key in a:  # maxima and counts the same; the energies and the solves' average errors summed in another order
        if key in ("kinetic_energy", "potential_energy", "divergence_error", "density_solve_error"):
            np.testing.assert_allclose(b[key], a[key], rtol=SUM_ORDER_RTOL, atol=0.0)
        else:
            assert np.array_equal(a[key], b[key]), key


@pytest.mark.parametrize(
    "numerics",
    [{}, {"free_liquid_rule": "outside_vessels"}, {"tension_treatment": "tic"}],
    # who records the pair list (cosim.fluid.wcsph_step.pair_recording): the first walk under the free-surface rule
    # and under the tensile-instability control, the force pass under 'outside_vessels'
    ids=["recorded-by-first-walk", "recorded-by-force-pass", "tic-recorded-by-first-walk"],
)
@pytest.mark.parametrize("dim", [2, 3])
def test_wcsph_without_pair_tables_walks_the_neighbours_again_to_the_same_state(dim, numerics):
    # without tables the force pass and the density rate walk the cells for the neighbours the pass that records the
    # list found, in the same order: the same terms in the same order, so the same state to the bit and nothing
    # allocated for the tables
    ref = _shaken_tank(dim, "wcsph", CPU_LAYOUT, **numerics)
    walking = _shaken_tank(dim, "wcsph", replace(CPU_LAYOUT, pair_tables=False), **numerics)
    assert walking.step.scratch.pairs.index.shape == (1, 1) and ref.step.scratch.pairs.index.shape[0] == ref.n_particles
    assert np.array_equal(ref.positions(), walking.positions())
    assert np.array_equal(ref.state.v.numpy(), walking.state.v.numpy())
    assert np.array_equal(ref.state.rho.numpy(), walking.state.rho.numpy())
    assert np.array_equal(ref.vessel_wrenches(), walking.vessel_wrenches())
    a, b = ref.history(), walking.history()
    assert len(a["dt"]) > 5 and all(np.array_equal(a[key], b[key]) for key in a)


@pytest.mark.parametrize("lanes", [1, 3])
def test_a_devices_diagnostics_are_read_lane_by_lane_without_a_device_copy(lanes, monkeypatch):
    # what a CUDA solver reads back after an interval (cosim.fluid.diagnostics.read_lane_rows): the leading rows of
    # every lane, each lane's read a contiguous view (a non-contiguous one would cost warp a device copy first)
    import warp as wp

    from cosim.fluid.diagnostics import read_lane_rows

    rows = wp.array(np.arange(lanes * 10 * 4, dtype=np.float32).reshape(lanes, 10, 4), device="cpu")
    numpy = wp.array.numpy
    views = []

    def spy(self):
        views.append(self.is_contiguous)
        return numpy(self)

    monkeypatch.setattr(wp.array, "numpy", spy)
    out = read_lane_rows(rows, 6)
    assert np.array_equal(out, numpy(rows)[:, :6])
    assert views == [True] * lanes


def test_on_cuda_a_gauss_seidel_density_solve_keeps_a_row_per_particle_in_the_pair_tables(monkeypatch):
    cuda, cpu = SimpleNamespace(is_cuda=True), SimpleNamespace(is_cuda=False)
    assert layout_for(cuda) == CUDA_LAYOUT and layout_for(cpu) == layout_for(cpu, sweeps=True) == CPU_LAYOUT
    sweeping = layout_for(cuda, sweeps=True)
    assert sweeping == CUDA_SWEEP_LAYOUT and not sweeping.pairs_by_column  # the sweeps' tables a row per particle, as on the CPU...
    assert (sweeping.interleaved_reduction, sweeping.atomic_replicas) == (CUDA_LAYOUT.interleaved_reduction, CUDA_LAYOUT.atomic_replicas)  # ...the rest CUDA's

    # the solver asks for the sweeping layout exactly when its density solve sweeps
    asked = []
    monkeypatch.setattr(solver_module, "layout_for", lambda device, sweeps=False: asked.append(sweeps) or CPU_LAYOUT)
    tank = VesselSpec(name="tank", inner_width=0.1, inner_depth=0.1, inner_height=0.15)
    for solver, iteration in (("dfsph", "gauss_seidel"), ("dfsph", "jacobi"), ("wcsph", "gauss_seidel")):
        cfg = FluidConfig(dim=2, spacing=0.005, pressure_solver=solver, density_iteration=iteration, max_expected_speed=1.5,
                          domain_min=(-0.15, -0.15, -0.05), domain_max=(0.15, 0.15, 0.25))
        FluidSolver(cfg, [tank], [Pose()], fill_vessel(tank, 0.03, cfg))
    assert asked == [True, False, False]
