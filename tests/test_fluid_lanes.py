"""A CPU substep split over threads (``cosim.fluid.lanes``): the liquid must evolve to the bit as on one thread,
whatever the number of lanes, with the lanes replaying their graphs at once or one after the other on one thread, or
run uncaptured one after the other; only the energies' float sums may round differently, being summed per lane."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import warp as wp

from cosim.errors import InputError
from cosim.fluid.config import DensityIteration, FluidConfig, PressureSolver
from cosim.fluid.diagnostics import DIAG_KINETIC_ENERGY, DIAG_MAX_SPEED, N_DIAG_FLOAT, combine_lanes
from cosim.fluid import lanes
from cosim.fluid.lanes import LANE_CHUNK, MIN_PARTICLES_PER_LANE, available_cores, item_kernel, lane_count, lane_sizes
from cosim.fluid.solver import FluidSolver
from tests.support.shaken_tank import SOLVER_VARIANTS, shake, tank

# Relative rounding of a float32 energy summed in two parts instead of one (a few ulps of the total).
ENERGY_SUM_RTOL = 1e-5
ENERGY_KEYS = ("kinetic_energy", "potential_energy")
ACROSS = 16  # 128 particles: too few for 2 automatic lanes, so the tests ask for them
SHAKE = dict(intervals=12, tilt=0.2)


def _assert_same_run(fluid: FluidSolver, reference: FluidSolver) -> None:
    assert fluid.step_count == reference.step_count
    for read in (FluidSolver.positions, FluidSolver.velocities, FluidSolver.densities, FluidSolver.pressures, FluidSolver.vessel_wrenches):
        np.testing.assert_array_equal(read(fluid), read(reference))
    for key, values in reference.history().items():
        if key in ENERGY_KEYS:
            np.testing.assert_allclose(fluid.history()[key], values, rtol=ENERGY_SUM_RTOL, err_msg=key)
        else:
            np.testing.assert_array_equal(fluid.history()[key], values, err_msg=key)


class _Alternating:
    """A replay choice that takes the lanes at once and one thread in turn, interval by interval."""

    def __init__(self):
        self.next = True

    def parallel(self) -> bool:
        return self.next

    def record(self, parallel: bool, substeps: int, wall_s: float) -> None:
        self.next = not parallel


@pytest.mark.parametrize(("solver", "iteration"), SOLVER_VARIANTS)
@pytest.mark.slow
def test_lanes_give_the_single_thread_run_to_the_bit(solver, iteration):
    one = tank(solver, ACROSS, threads=1, iteration=iteration)
    shake(one, **SHAKE)
    assert one.lanes.count == 1
    for threads, graphs in ((2, True), (3, True), (2, False)):
        fluid = tank(solver, ACROSS, graphs, threads, iteration)
        fluid.lanes.choice = _Alternating()
        shake(fluid, **SHAKE)
        assert fluid.lanes.count == threads
        assert fluid.runner.replays_graphs == graphs and fluid.graph_capture_error is None  # it replayed the lanes' graphs
        if graphs:  # both ways of replaying ran
            assert fluid.lanes.substeps_at_once > 0 and fluid.lanes.substeps_one_thread > 0
        _assert_same_run(fluid, one)
    assert one.history()["density_iterations" if solver is PressureSolver.DFSPH else "active"].max() > 0  # the solves ran


def test_lanes_that_sleep_at_every_barrier_give_the_same_run(monkeypatch):
    """No spins: every lane that waits sleeps (a futex on Linux) until the last lane wakes it; a lost wake-up would
    hang here, a barrier that let a lane through early would change the particles."""
    monkeypatch.setattr(lanes, "SPINS_BEFORE_SLEEP", 0)
    solver, iteration = PressureSolver.DFSPH, DensityIteration.GAUSS_SEIDEL
    one = tank(solver, ACROSS, threads=1, iteration=iteration)
    shake(one, **SHAKE)
    fluid = tank(solver, ACROSS, True, 2, iteration)
    fluid.lanes.choice = _Alternating()
    shake(fluid, **SHAKE)
    assert fluid.lanes.substeps_at_once > 0
    _assert_same_run(fluid, one)


@item_kernel
def _mark_items(hits: wp.array(dtype=wp.int32), owner: wp.array(dtype=wp.int32), mark: int):
    i = wp.tid()
    hits[i] += 1
    owner[i] = mark


def test_lanes_compute_every_item_once():
    assert [arg.label for arg in _mark_items.adj.args] == ["lane", "hits", "owner", "mark"]
    for count in (1, 7, LANE_CHUNK, 864, 1001):
        for lanes in (1, 2, 3, 8):
            hits = wp.zeros(count, dtype=wp.int32, device="cpu")
            owner = wp.zeros(count, dtype=wp.int32, device="cpu")
            sizes = lane_sizes(count, lanes)
            for lane, size in enumerate(sizes):
                wp.launch(_mark_items, dim=size, inputs=[wp.vec2i(lane, lanes), hits, owner, lane], device="cpu")
            np.testing.assert_array_equal(hits.numpy(), 1)
            # chunks of LANE_CHUNK items dealt out in turn; the shares differ by at most one chunk
            np.testing.assert_array_equal(owner.numpy(), (np.arange(count) // LANE_CHUNK) % lanes)
            assert max(sizes) - min(sizes) <= LANE_CHUNK


def test_lane_count():
    cpu, cuda = SimpleNamespace(is_cuda=False), SimpleNamespace(is_cuda=True)
    assert lane_count(4, 10, cpu) == 4  # asked for: given, however few particles
    assert lane_count(4, 10**6, cuda) == 1
    assert lane_count(0, MIN_PARTICLES_PER_LANE - 1, cpu) == 1
    assert lane_count(0, 10**6, cpu) == available_cores()
    assert lane_count(0, 2 * MIN_PARTICLES_PER_LANE, cpu) == min(2, available_cores())


def test_combine_lanes_takes_maxima_and_sums():
    lanes_f = np.zeros((2, 3, N_DIAG_FLOAT), dtype=np.float32)
    lanes_i = np.arange(2 * 3 * 4, dtype=np.int32).reshape(2, 3, 4)
    lanes_f[0, :, DIAG_MAX_SPEED], lanes_f[1, :, DIAG_MAX_SPEED] = [1.0, 5.0, 2.0], [3.0, 4.0, 2.5]
    lanes_f[0, :, DIAG_KINETIC_ENERGY], lanes_f[1, :, DIAG_KINETIC_ENERGY] = [1.0, 2.0, 3.0], [0.5, 0.25, 0.0]
    rows_f, rows_i = combine_lanes(lanes_f, lanes_i)
    np.testing.assert_array_equal(rows_f[:, DIAG_MAX_SPEED], [3.0, 5.0, 2.5])
    np.testing.assert_array_equal(rows_f[:, DIAG_KINETIC_ENERGY], [1.5, 2.25, 3.0])
    np.testing.assert_array_equal(rows_i, lanes_i[0] + lanes_i[1])
    assert rows_f.dtype == np.float32 and rows_i.dtype == np.int32


def test_cpu_threads_out_of_range_is_refused():
    with pytest.raises(InputError, match=r"fluid.cpu_threads: .*\[0, 256\]"):
        replace(FluidConfig(), cpu_threads=-1)
    with pytest.raises(InputError, match="fluid.cpu_threads: must be an integer"):
        replace(FluidConfig(), cpu_threads=1.5)


# Child processes (run under a time limit, so that a hang fails the test instead of stalling the suite): a 2-lane
# tank whose substeps have been captured and replayed, then SCRIPT's interruption of a replay, then the check that
# the lanes are marked aborted and the next interval is refused.
CHILD_SETUP = """
import threading, warp as wp
from cosim.errors import SimulationError
from cosim.fluid import lanes
from cosim.fluid.config import PressureSolver
from tests.support.shaken_tank import tank
fluid = tank(PressureSolver.DFSPH, 16, threads=2)
fluid.advance(0.01)
fluid.advance(0.01)  # captured and replayed by both lanes
assert fluid.runner.replays_graphs
"""
CHILD_CHECK = """
assert fluid.lanes.aborted
try:
    fluid.advance(0.01)
except SimulationError as exc:
    print("refused:", exc)
"""


def _assert_interruption_is_contained(script: str) -> None:
    root = Path(__file__).resolve().parents[1]
    done = subprocess.run([sys.executable, "-c", CHILD_SETUP + script + CHILD_CHECK], cwd=root, capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "refused: fluid: an earlier interval was interrupted" in done.stdout


def test_a_failing_lane_raises_instead_of_leaving_the_others_waiting():
    """Lane 1 fails before its first substep: lane 0 would wait at the first barrier forever without the abort."""
    _assert_interruption_is_contained("""
real = wp.capture_launch
def failing(graph):
    if threading.current_thread() is not threading.main_thread():
        raise RuntimeError("lane failed")
    real(graph)
wp.capture_launch = failing
try:
    fluid.advance(0.01)
except RuntimeError as exc:
    assert str(exc) == "lane failed", exc
else:
    raise AssertionError("the failing lane's error was not raised")
wp.capture_launch = real
""")


def test_an_interrupted_wait_for_the_lanes_refuses_further_intervals():
    """Ctrl-C while lane 0 waits for the other lanes: a lane may still be replaying, so the solver must refuse the next
    interval (starting one would hand that lane a second job and confuse their completions) instead of racing it."""
    _assert_interruption_is_contained("""
real = lanes._LaneThread.join
def interrupted(self):
    raise KeyboardInterrupt  # Ctrl-C while lane 0 waits for the others, which may still be running
lanes._LaneThread.join = interrupted
try:
    fluid.advance(0.01)
except KeyboardInterrupt:
    pass
else:
    raise AssertionError("the interrupt was not raised")
lanes._LaneThread.join = real
""")
