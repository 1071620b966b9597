"""The substep as a recorded program, written by plain stage functions.

A pressure solver's substep is a sequence of stage functions of (model, state, scratch), called in the order the
substep runs them (``cosim.fluid.wcsph_step``, ``cosim.fluid.dfsph_step``). A stage function launches its kernels
through a :class:`Recorder`, every kernel argument by name (``cosim.fluid.launch``). Calling the substep once per
buffer parity records it as a program of stages with the arguments bound (:class:`cosim.fluid.lanes.Stage`,
:class:`cosim.fluid.lanes.Loop`), which ``cosim.fluid.runner`` runs operation by operation, captures as graphs or
replays on CPU threads: the stage functions know nothing of either.

A particle kernel (``cosim.fluid.lanes.item_kernel``) is launched with :meth:`Recorder.launch`: the recorder splits
its items over the CPU lanes (``cosim.fluid.lanes``; the kernel's ``lane`` parameter, which the decorator adds, is
supplied here) and puts a barrier after it. A
bookkeeping kernel of a few threads runs on one lane (:meth:`Recorder.launch_on_lane`), so do warp's memsets and
sorts (:meth:`Recorder.call`). Stages recorded inside :meth:`Recorder.together` share their barriers; inside
:meth:`Recorder.loop` they repeat while a device flag is set (``wp.capture_while``).
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Callable, Iterator

import warp as wp

from cosim.fluid.lanes import Lanes, Loop, PerLane, Program, Stage, lane_sizes, together
from cosim.fluid.launch import record_launch


class Recorder:
    """Records the launches of stage functions into :attr:`program`, split over ``lanes``."""

    def __init__(self, lanes: Lanes):
        self.lanes = lanes
        self.program: list[Stage | Loop] = []
        self._bodies: list[list[Stage | Loop]] = [self.program]  # the innermost open loop's body last
        self._group: list[Stage] | None = None  # the stages of an open together()

    def launch(self, kernel, items: int, /, **args: Any) -> None:
        """``kernel`` (an ``item_kernel``) over ``items`` items, each lane its share (``cosim.fluid.lanes.lane_item``);
        ``args`` by the kernel's parameter names, a :class:`PerLane` value giving each lane its own."""
        parts = []
        for lane, size in enumerate(lane_sizes(items, self.lanes.count)):
            if size == 0:
                parts.append(())
                continue
            bound = {name: value[lane] if isinstance(value, PerLane) else value for name, value in args.items()}
            bound["lane"] = wp.vec2i(lane, self.lanes.count)
            parts.append((record_launch(kernel, size, self.lanes.device, bound),))
        self._add(Stage(tuple(parts)))

    def launch_on_lane(self, kernel, dim, /, **args: Any) -> None:
        """``kernel`` over ``dim`` threads on lane 0 alone (the others wait), ``args`` by name."""
        self.call(0, record_launch(kernel, dim, self.lanes.device, args))

    def call(self, lane: int, *ops: Callable[[], None]) -> None:
        """Operations without lanes of their own (memsets, sorts, recorded launches) on lane ``lane`` (modulo the
        lane count), in order; the others wait."""
        self._add(self.lanes.on_lane(lane, *ops))

    @contextmanager
    def together(self) -> Iterator[None]:
        """The stages recorded inside run between the same two barriers: each lane runs its parts of them in the
        order recorded, so they must be independent across lanes."""
        outer, self._group = self._group, []
        try:
            yield
        finally:
            group, self._group = self._group, outer
            if group:
                self._add(together(*group))

    @contextmanager
    def loop(self, flag: wp.array) -> Iterator[None]:
        """The stages recorded inside repeat while ``flag[0]`` is non-zero (``wp.capture_while``; its first stage
        runs at least once)."""
        if self._group is not None:
            raise RuntimeError("a loop cannot share its barriers with other stages")
        body: list[Stage | Loop] = []
        self._bodies.append(body)
        try:
            yield
        finally:
            self._bodies.pop()
            self._add(Loop(flag, tuple(body)))

    def _add(self, stage: Stage | Loop) -> None:
        if self._group is not None:
            self._group.append(stage)
        else:
            self._bodies[-1].append(stage)


def record_program(lanes: Lanes, write: Callable[[Recorder], None]) -> Program:
    """The program ``write`` records (a substep's stage functions, called with one recorder)."""
    recorder = Recorder(lanes)
    write(recorder)
    return recorder.program
