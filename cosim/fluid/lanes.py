"""A substep split over CPU threads ("lanes"): warp runs a CPU kernel on one thread (NVIDIA/warp#1309), so on its
own the solver leaves every other core idle.

Each lane launches the particle kernels over its own share of the particles (chunks dealt out in turn,
:func:`lane_item`) and every lane waits for the others between stages
(:func:`barrier_wait`, a barrier in native code inside the captured graph that spins briefly, then sleeps), so each
lane's substep is one graph of warp's CPU operation stream that its own thread replays. The split changes no result:
every kernel computes each particle as before, and what the lanes accumulate together (the solves' error sums, the
diagnostics' counts and maxima) is kept per lane and combined in a fixed order, as integers or maxima where it steers
the run. The same operations are also captured as one graph of every lane's share in turn, for one thread: where the
cores are shared with other processes, the lanes stall each other at the barriers, and the replay runs that way
instead, as timing both shows (``cosim.fluid.lane_choice``). Without graphs (the first interval, ``graphs=False``)
the lanes' shares run one after the other on the calling thread.

A stage is the unit between two barriers: :class:`Stage` (the operations each lane runs) or :class:`Loop` (a
``wp.capture_while`` loop of stages on a device flag); the stage functions of the physics record them without
knowing of lanes (``cosim.fluid.program``). Nor do the kernels: a kernel of independent items is declared
:func:`item_kernel`, its body computes item ``wp.tid()``, and the split is compiled in from outside.
"""

from __future__ import annotations

import ast
import ctypes
import functools
import inspect
import os
import platform
import sys
import textwrap
import threading
import time
import weakref
from dataclasses import dataclass
from typing import Callable, Sequence, Union

import warp as wp

from cosim.fluid.lane_choice import ReplayChoice
from cosim.fluid.launch import record_launch

# Fewest particles per lane the automatic thread count gives a lane: 400 particles get 2 lanes, fewer one. A resting
# 2-D tank of 400 particles, the smallest the throughput benchmark builds, already runs more particle-steps per
# second on 2 lanes than on one under both solvers (docs/tuning.md); nothing smaller is known to gain.
MIN_PARTICLES_PER_LANE = 200
# Spins (x86 ``pause`` / arm ``yield`` hints) before a waiting lane goes to sleep until the barrier opens: about
# 40-100 us, several stages' worth, so a lane that is running is waited for on the spot, while one whose core the OS
# gave to another process is waited for asleep, its core left to that lane or process instead of spun on.
SPINS_BEFORE_SLEEP = 4000
# Items are dealt out to the lanes in chunks of this many, in turn: the particles are in cell order, so contiguous
# halves would give one lane the bulk and the other the sparse stream (more neighbour pairs in one half, and every
# wall sample that touches liquid in one half of the walls; docs/tuning.md). 16 float32 or
# int32 values fill one 64-byte cache line and 16 vec3 three, so two lanes do not write into one line.
LANE_CHUNK = wp.constant(16)


# Linux futex operations (linux/futex.h): sleep while a word holds an expected value; wake the sleepers on a word.
FUTEX_WAIT_PRIVATE = 128
FUTEX_WAKE_PRIVATE = 129
# The futex system call's number on the Linux machines warp builds for (asm/unistd.h); elsewhere a waiting lane
# yields its core on every check after the spins instead of sleeping.
FUTEX_SYSCALL = {"x86_64": 202, "aarch64": 98}


# The barrier's native code is for the CPU only: CUDA runs one lane and never launches it. NVRTC, which compiles the
# module whenever warp loads it for a GPU (wp.force_load, ahead-of-time builds), has no GCC atomics, so there it
# compiles to nothing (tests/test_cuda_compile.py). The waiting lanes' sleep is the word-wait of a futex on the
# generation: the last lane to arrive advances it and wakes the sleepers only when some lane counted itself asleep
# (sequentially consistent order on both sides, so either the sleeper sees the new generation, which makes its
# futex call return at once, or the last lane sees the sleeper and wakes it).
@wp.func_native(
    """
#if !defined(__CUDA_ARCH__)
typedef long (*syscall_t)(long, ...);
if (__atomic_load_n(&state.data[2], __ATOMIC_ACQUIRE) != 0) {
    return;
}
const int generation = __atomic_load_n(&state.data[1], __ATOMIC_ACQUIRE);
if (__atomic_add_fetch(&state.data[0], 1, __ATOMIC_ACQ_REL) == parties) {
    __atomic_store_n(&state.data[0], 0, __ATOMIC_RELAXED);
    __atomic_store_n(&state.data[1], generation + 1, __ATOMIC_SEQ_CST);
    if (futex != 0 && __atomic_load_n(&state.data[3], __ATOMIC_SEQ_CST) != 0) {
        ((syscall_t)os_fn)((long)futex, (long)&state.data[1], (long)wake_op, (long)0x7fffffff);
    }
    return;
}
for (long spins = 0; __atomic_load_n(&state.data[1], __ATOMIC_ACQUIRE) == generation
                     && __atomic_load_n(&state.data[2], __ATOMIC_ACQUIRE) == 0; ++spins) {
    if (spins < spins_before_sleep) {
#if defined(__x86_64__) || defined(__i386__)
        __builtin_ia32_pause();
#elif defined(__aarch64__)
        __asm__ __volatile__("yield");
#endif
    } else if (futex != 0) {
        __atomic_add_fetch(&state.data[3], 1, __ATOMIC_SEQ_CST);
        ((syscall_t)os_fn)((long)futex, (long)&state.data[1], (long)wait_op, (long)generation, (long)0);
        __atomic_sub_fetch(&state.data[3], 1, __ATOMIC_SEQ_CST);
    } else {
        ((void (*)())os_fn)();
    }
}
#endif
"""
)
def barrier_wait(
    state: wp.array(dtype=wp.int32), parties: int, spins_before_sleep: int, futex: int, wait_op: int, wake_op: int, os_fn: wp.uint64
): ...


@wp.kernel
def lane_barrier(
    state: wp.array(dtype=wp.int32), parties: int, spins_before_sleep: int, futex: int, wait_op: int, wake_op: int, os_fn: wp.uint64
):
    """One thread: return once all ``parties`` lanes have arrived, or at once after an abort (state: [arrived,
    generation, aborted, asleep], zeroed at start). A waiting lane spins ``spins_before_sleep`` times, then sleeps
    on the futex system call ``futex`` (``os_fn``: libc's ``syscall``), or where ``futex`` is 0 yields its core on
    every further check (``os_fn``: the OS's yield)."""
    barrier_wait(state, parties, spins_before_sleep, futex, wait_op, wake_op, os_fn)


def _futex_syscall() -> int:
    """The futex system call's number here; 0 where there is none (not Linux, or an unknown machine)."""
    return FUTEX_SYSCALL.get(platform.machine(), 0) if sys.platform.startswith("linux") else 0


def _os_function(futex: int) -> int:
    """Address of what a waiting lane calls after its spins: libc's ``syscall`` where it sleeps on a futex, else the
    OS call that gives the core to another thread (sched_yield; SwitchToThread on Windows)."""
    if sys.platform == "win32":
        return ctypes.cast(ctypes.windll.kernel32.SwitchToThread, ctypes.c_void_p).value
    libc = ctypes.CDLL(None)
    return ctypes.cast(libc.syscall if futex else libc.sched_yield, ctypes.c_void_p).value


def _wake_sleepers(generation_address: int, futex: int) -> None:
    """Wake every lane asleep on the barrier's generation word (after an abort)."""
    if futex:
        ctypes.CDLL(None).syscall(ctypes.c_long(futex), ctypes.c_void_p(generation_address), ctypes.c_long(FUTEX_WAKE_PRIVATE), ctypes.c_long(0x7FFFFFFF))


def available_cores() -> int:
    """CPU cores this process may run on (its affinity mask where the OS has one)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def lane_count(threads: int, n_particles: int, device) -> int:
    """Lanes for a solver: 1 on CUDA (the device is parallel already), ``threads`` on the CPU, or with 0 (auto)
    one per available core, at most one per :data:`MIN_PARTICLES_PER_LANE` particles."""
    if device.is_cuda:
        return 1
    if threads > 0:
        return threads
    return max(1, min(available_cores(), n_particles // MIN_PARTICLES_PER_LANE))


@wp.func
def lane_item(tid: int, lane: wp.vec2i) -> int:
    """The item the ``tid``-th thread of lane ``lane[0]`` of ``lane[1]`` computes: the items are dealt out to the
    lanes in turn in chunks of :data:`LANE_CHUNK`."""
    return ((tid // LANE_CHUNK) * lane[1] + lane[0]) * LANE_CHUNK + tid % LANE_CHUNK


class _ItemOfLane(ast.NodeTransformer):
    """A kernel's function definition rewritten for a share of its items: a first parameter ``lane`` (wp.vec2i:
    the launch's lane, lane count) and every ``wp.tid()`` read through ``lane_item``."""

    def visit_FunctionDef(self, node: ast.FunctionDef) -> ast.FunctionDef:
        node.decorator_list = []
        node.args.args.insert(0, ast.arg("lane", annotation=ast.Attribute(ast.Name("wp", ast.Load()), "vec2i", ast.Load())))
        self.generic_visit(node)
        return node

    def visit_Call(self, node: ast.Call) -> ast.AST:
        self.generic_visit(node)
        tid = node.func
        if isinstance(tid, ast.Attribute) and tid.attr == "tid" and isinstance(tid.value, ast.Name) and tid.value.id == "wp":
            return ast.Call(ast.Name("lane_item", ast.Load()), [node, ast.Name("lane", ast.Load())], [])
        return node


def item_kernel(func):
    """``@wp.kernel`` for a one-dimensional kernel whose threads compute independent items (particles, wall
    particles, sweep threads), which :meth:`cosim.fluid.program.Recorder.launch` splits over the lanes: in its body
    ``wp.tid()`` is the item. It is compiled from its own source with a first parameter ``lane`` (the launch's lane,
    lane count), which the recorder supplies (one lane of one on CUDA), and each ``wp.tid()`` read as
    ``lane_item(wp.tid(), lane)`` (:func:`lane_item`): the physics never names the lanes, and computes each item as
    a plain kernel would. (warp cannot add a parameter to a kernel from outside, nor offset or stride its thread
    index at launch, so the split is compiled in; the generated code is that of the same kernel written with the
    ``lane`` parameter by hand.)"""
    source = ast.unparse(ast.fix_missing_locations(_ItemOfLane().visit(ast.parse(textwrap.dedent(inspect.getsource(func))))))
    # the kernel's function defined in its own module's namespace, with lane_item from here as a closure variable
    factory = f"def define_kernel(lane_item):\n{textwrap.indent(source, '    ')}\n    return {func.__name__}\n"
    scope: dict = {}
    exec(compile(factory, inspect.getsourcefile(func), "exec"), func.__globals__, scope)
    return wp.Kernel(scope["define_kernel"](lane_item), key=func.__name__, module=wp.get_module(func.__module__), source=source)


def lane_sizes(count: int, lanes: int) -> list[int]:
    """How many of ``count`` items each lane computes (:func:`lane_item`)."""
    sizes = [0] * lanes
    for chunk in range(0, count, LANE_CHUNK):
        sizes[(chunk // LANE_CHUNK) % lanes] += min(LANE_CHUNK, count - chunk)
    return sizes


@dataclass(frozen=True)
class Stage:
    """One step between barriers: ``parts[lane]`` are the operations (recorded launches, memsets, sorts) that lane
    runs, in order."""

    parts: tuple[tuple[Callable[[], None], ...], ...]


def together(*stages: Stage) -> Stage:
    """Independent stages run between the same two barriers: each lane runs its parts of all of them, in order."""
    return Stage(tuple(sum(parts, ()) for parts in zip(*(stage.parts for stage in stages))))


@dataclass(frozen=True)
class Loop:
    """``wp.capture_while(flag, body)``: the stages of ``body`` repeated while ``flag[0]`` is non-zero. Every lane
    reads the flag after the body's last barrier, and waits at one more barrier after the loop before any stage can
    write the flag again (the DFSPH solves' first stages set it for the next solve), so all lanes take the same
    number of iterations."""

    flag: wp.array
    body: tuple[Union[Stage, "Loop"], ...]


Program = Sequence[Union[Stage, Loop]]


class PerLane(tuple):
    """An argument with one value per lane (e.g. each lane's row of a diagnostics array); a split launch
    (``cosim.fluid.program.Recorder.launch``) passes lane L its L-th value."""


def run_serial(program: Program, call: Callable[[Callable[[], None]], None] | None = None) -> None:
    """Every lane's operations in lane order on the calling thread (uncaptured, or captured as one graph); ``call``,
    when given, runs each operation instead (a profiler's hook: ``call(op)`` must call ``op()``)."""
    for item in program:
        if isinstance(item, Loop):
            wp.capture_while(item.flag, lambda body=item.body: run_serial(body, call))
        else:
            for part in item.parts:
                for op in part:
                    if call is None:
                        op()
                    else:
                        call(op)


class _LaneThread:
    """A thread that runs one job at a time when asked: two locks hand each job over and back, cheaper than a thread
    pool's futures, whose submit and wait per stage are a visible share of a pour's host time (docs/tuning.md)."""

    _STOP = object()

    def __init__(self, name: str):
        self._go = threading.Lock()
        self._go.acquire()
        self._done = threading.Lock()
        self._done.acquire()
        self._job = None
        self._error: BaseException | None = None
        threading.Thread(target=self._serve, name=name, daemon=True).start()

    def _serve(self) -> None:
        while True:
            self._go.acquire()
            job, self._job = self._job, None  # holds no reference to the job's owner between jobs
            if job is _LaneThread._STOP:
                return
            try:
                job()
            except BaseException as exc:  # handed to the caller by join()
                self._error = exc
            del job
            self._done.release()

    def start(self, job: Callable[[], None]) -> None:
        self._job = job
        self._go.release()

    def join(self) -> BaseException | None:
        """Waits for the job started last; returns what it raised, if anything."""
        self._done.acquire()
        error, self._error = self._error, None
        return error

    def stop(self) -> None:
        self._job = _LaneThread._STOP
        self._go.release()


def _stop_threads(threads: list[_LaneThread]) -> None:
    for thread in threads:
        thread.stop()


@dataclass(frozen=True)
class LaneGraphs:
    """A program captured for the lanes: ``parallel[L]`` lane L's graph (its operations, a barrier after every
    stage), ``serial`` every lane's operations in lane order without barriers, for one thread."""

    parallel: tuple
    serial: object


class Lanes:
    """The lanes of one solver: their graphs of a program and the threads that replay them."""

    def __init__(self, count: int, device):
        self.count = count
        self.device = device
        self._barrier_state = wp.zeros(4, dtype=wp.int32, device=device)
        self._futex = _futex_syscall()
        self._barrier = None
        self._threads: list[_LaneThread] | None = None  # lanes 1.. (lane 0 runs on the caller's thread)
        self._aborted = False
        self.choice = ReplayChoice()  # all lanes at once or one thread, interval by interval
        self.substeps_at_once = 0  # substeps replayed by all lanes at once, and by one thread (more than one lane)
        self.substeps_one_thread = 0

    def on_lane(self, lane: int, *ops: Callable[[], None]) -> Stage:
        """``ops`` on one lane (``lane`` taken modulo the lane count); the others only wait."""
        lane %= self.count
        return Stage(tuple(tuple(ops) if k == lane else () for k in range(self.count)))

    def _wait(self) -> None:
        if self._barrier is None:
            self._barrier = record_launch(
                lane_barrier, 1, self.device,
                dict(
                    state=self._barrier_state, parties=self.count, spins_before_sleep=SPINS_BEFORE_SLEEP, futex=self._futex,
                    wait_op=FUTEX_WAIT_PRIVATE, wake_op=FUTEX_WAKE_PRIVATE, os_fn=wp.uint64(_os_function(self._futex)),
                ),
            )
        self._barrier()

    def run_lane(self, program: Program, lane: int) -> None:
        """Lane ``lane``'s operations with a barrier after every stage: to be captured as that lane's graph."""
        for item in program:
            if isinstance(item, Loop):
                wp.capture_while(item.flag, lambda body=item.body: self.run_lane(body, lane))
            else:
                for op in item.parts[lane]:
                    op()
            self._wait()  # after a loop too: no lane may set the flag again before every lane has read it

    def capture(self, program: Program) -> LaneGraphs:
        """``program`` captured for the lanes (capturing runs nothing): one graph per lane with the barriers, and one
        graph of every lane's share in turn for one thread (a single lane's are the same graph)."""
        serial = self._capture(lambda: run_serial(program))
        if self.count == 1:
            return LaneGraphs((serial,), serial)
        return LaneGraphs(tuple(self._capture(lambda lane=lane: self.run_lane(program, lane)) for lane in range(self.count)), serial)

    def _capture(self, record: Callable[[], None]):
        with wp.ScopedCapture(device=self.device) as capture:
            record()
        return capture.graph

    @property
    def aborted(self) -> bool:
        """A replay was abandoned (an error or an interrupt in one lane): the particle state is undefined."""
        return self._aborted

    def replay(self, substeps: Sequence[LaneGraphs]) -> None:
        """The captured ``substeps`` in order, all lanes at once or every lane's share on the calling thread, as
        :attr:`choice` says (the same results to the bit); it is told the wall time each way took."""
        if self.count == 1:
            self._replay_lane([graphs.serial for graphs in substeps])
            return
        parallel = self.choice.parallel()
        start = time.perf_counter()
        if parallel:
            self._replay_at_once([[graphs.parallel[lane] for graphs in substeps] for lane in range(self.count)])
        else:
            self._replay_lane([graphs.serial for graphs in substeps])
        self.choice.record(parallel, len(substeps), time.perf_counter() - start)
        self.substeps_at_once += len(substeps) if parallel else 0
        self.substeps_one_thread += 0 if parallel else len(substeps)

    def _replay_at_once(self, schedules: Sequence[Sequence]) -> None:
        """Lane L replays the graphs ``schedules[L]`` in order, all lanes at once (lane 0 on the calling thread);
        returns when every lane has finished. Should a lane fail or the caller be interrupted (Ctrl-C), the barriers
        are opened for good so that no lane waits forever for it, every lane is waited for, and the first error is
        raised; :attr:`aborted` then stays true, also when the wait itself is interrupted (a lane may still be
        running, so no replay may follow)."""
        if self._threads is None:
            self._threads = [_LaneThread(f"cosim-fluid-lane-{k}") for k in range(1, self.count)]
            weakref.finalize(self, _stop_threads, self._threads)
        started, errors = [], []
        try:
            for thread, schedule in zip(self._threads, schedules[1:]):
                thread.start(functools.partial(self._replay_lane, schedule))
                started.append(thread)
            self._replay_lane(schedules[0])
        except BaseException:
            self._abort()
            raise
        finally:
            try:
                errors = [thread.join() for thread in started]  # waits; the first error is raised below or above
            except BaseException:  # interrupted while waiting: a lane may still run, so no replay may follow
                self._abort()
                raise
        for error in errors:
            if error is not None:
                raise error

    def _replay_lane(self, graphs: Sequence) -> None:
        try:
            for graph in graphs:
                wp.capture_launch(graph)
        except BaseException:
            self._abort()
            raise

    def _abort(self) -> None:
        self._aborted = True
        state = self._barrier_state.numpy()  # CPU memory: the waiting lanes see it
        state[2] = 1
        state[1] += 1  # a lane about to sleep on the old generation returns at once
        _wake_sleepers(self._barrier_state.ptr + state.itemsize, self._futex)
