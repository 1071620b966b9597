"""Running a pressure solver's substeps: recorded, captured as graphs, split over CPU lanes, from outside the physics.

The substep of each buffer parity (the particle state is reordered from one buffer into the other every substep)
is recorded once from the step's stage functions (``cosim.fluid.program``). The first interval runs the recorded
operations one by one (which compiles the kernels and sizes the sort's scratch memory); after it, each lane's graph
of each parity is captured and every later interval replays them: a CUDA graph on a CUDA device (DFSPH's solve
loops become conditional nodes; the same results to the bit as the launches), on the CPU warp's operation stream
(APIC), which replays the launches in C++ without Python's per-launch argument handling, one graph per lane, each
lane's thread replaying its own share with barriers between the stages, or, where the cores are busy, one graph of
every lane's share replayed by one thread (``cosim.fluid.lanes``; the same results to the bit either way). Where capture fails the operations keep running one by one (:attr:`SubstepRunner.capture_error`).
"""

from __future__ import annotations

from typing import Callable

from cosim.errors import SimulationError
from cosim.fluid.lanes import LaneGraphs, Lanes, Program, run_serial
from cosim.fluid.model import FluidState
from cosim.fluid.program import Recorder, record_program

# a stage-function substep: (recorder, source buffer, destination buffer)
Substep = Callable[[Recorder, FluidState, FluidState], None]


class SubstepRunner:
    """Runs ``substep`` on two particle buffers, ``state`` (the current one) and ``spare``.

    capture: replay captured graphs from the second interval on (else the operations one by one, always).
    :attr:`operation_hook`: a profiler's hook (``cosim.bench.kernel_profile``): with substeps run one by one, each
    operation runs as ``operation_hook(op)``, which must call ``op()``; None: the operations are called directly.
    """

    def __init__(self, lanes: Lanes, substep: Substep, state: FluidState, spare: FluidState, capture: bool):
        self.lanes = lanes
        self._substep = substep
        self._buffers = (state, spare)
        self._parity = 0  # the buffer that holds the current state
        self._capture = capture
        self.capture_error: str | None = None
        self.operation_hook: Callable[[Callable[[], None]], None] | None = None
        self._programs: tuple[Program, Program] | None = None  # substeps from buffer 0 and from buffer 1
        self._graphs: tuple[LaneGraphs, LaneGraphs] | None = None  # from buffer 0, from buffer 1

    @property
    def state(self) -> FluidState:
        """The buffer that holds the liquid's current state."""
        return self._buffers[self._parity]

    @property
    def replays_graphs(self) -> bool:
        """The substeps are replayed as captured graphs."""
        return self._graphs is not None

    def invalidate(self) -> None:
        """Record the substep again before the next run (the arrays it was recorded with were replaced)."""
        self._programs = None
        self._graphs = None

    def run(self, count: int) -> None:
        """``count`` substeps: each lane replays its graphs (the lanes at once), or the operations run one by one
        (every lane's share in turn); the current buffer alternates with each substep."""
        if self.lanes.aborted:
            raise SimulationError("fluid: an earlier interval was interrupted inside its substeps; the liquid's state is undefined")
        if self._programs is None:
            a, b = self._buffers
            self._programs = (
                record_program(self.lanes, lambda rec: self._substep(rec, a, b)), record_program(self.lanes, lambda rec: self._substep(rec, b, a)),
            )
        parities = [(self._parity + k) % 2 for k in range(count)]
        if self._graphs is not None:
            self.lanes.replay([self._graphs[p] for p in parities])
        else:
            for p in parities:
                run_serial(self._programs[p], self.operation_hook)
        self._parity = (self._parity + count) % 2

    def capture_if_due(self) -> None:
        """After the first run: the lanes' graphs of both parities, or, where warp or the driver cannot capture
        them, the reason in :attr:`capture_error` (and the operations one by one from then on)."""
        if not self._capture or self._graphs is not None or self._programs is None:
            return
        try:
            graphs = tuple(self.lanes.capture(program) for program in self._programs)
        except Exception as exc:  # warp raises RuntimeError and others (e.g. no conditional nodes before CUDA 12.4)
            self._capture = False
            self.capture_error = f"{type(exc).__name__}: {exc}"
            return
        self._graphs = graphs
