"""Where a substep's device time goes: every kernel and memory operation of the fluid benchmark's resting block,
timed by warp's CUDA activity timing (a profile, not a benchmark: launches run one by one so each is timed).

    python -m cosim.bench.kernel_profile [--device cuda] [--cases 3:1000000:wcsph 2:10000:dfsph:jacobi] [--steps 20]
                                         [--top 12] [--pair-layouts rows columns packed] [--out DIR]

For each case (dim:particles:solver, for DFSPH optionally :gauss_seidel or :jacobi, its density iteration) the
block of ``cosim.bench.fluid_throughput`` settles for one interval of ``steps`` WCSPH substeps, then one more is timed: the wall time, the sum of the device activities (their
difference is the host's launch and synchronisation cost), and the ``top`` activities by total time, with their
count and milliseconds per substep. On the CPU, where warp times nothing per kernel, each operation of the substeps is
timed on the host instead (:class:`OperationTimer`, the solver's ``operation_hook``; a CPU launch returns
when it is done), the lanes' shares one after the other, by the thread's CPU time, which leaves out the moments
the OS gave the core to another process (on a shared machine a profile's wall times swing with the load).
``--pair-layouts`` profiles each case once per layout of the neighbour-pair tables (``rows``: a row per particle;
``columns``: slot-major, CUDA's; ``packed``: DFSPH's lists of each block of particles one after the other, the
CPU's, the CPU only; ``none``: WCSPH keeps no pair tables and its density rate walks the cells again, DFSPH rows;
:mod:`cosim.fluid.device_layout`, :mod:`cosim.fluid.pair_slots`), the rest of the device's layout kept:
the particles are the same under either, so the kernels' times compare the layouts alone.
Writes DIR/kernel_profile.md (atomically) besides printing it.
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

import warp as wp

from cosim.atomic_files import write_text_atomic
from cosim.bench.fluid_throughput import resting_block
from cosim.fluid.config import DensityIteration, FluidConfig, PressureSolver
from cosim.fluid.device_layout import layout_for
from cosim.fluid.runtime import resolve_device

# the speed targets' sizes (3-D 1M, 2-D 10k), each solver, DFSPH with either density iteration
DEFAULT_CASES = [f"{size}:{solver}" for size in ("3:1000000", "2:10000") for solver in ("wcsph", "dfsph:jacobi", "dfsph:gauss_seidel")]
# --pair-layouts: name -> the DeviceLayout fields of the pair tables
PAIR_LAYOUTS = {
    "rows": dict(pairs_by_column=False, pairs_packed=False, pair_tables=True),
    "columns": dict(pairs_by_column=True, pairs_packed=False, pair_tables=True),
    "packed": dict(pairs_by_column=False, pairs_packed=True, pair_tables=True),
    "none": dict(pairs_by_column=False, pairs_packed=False, pair_tables=False),  # WCSPH: the density rate walks again
}


def parse_case(text: str) -> tuple[int, int, PressureSolver, DensityIteration]:
    """``dim:particles:solver[:iteration]`` as (dim, particles, solver, DFSPH's density iteration)."""
    dim, n, solver, *iteration = text.split(":")
    return int(dim), int(n), PressureSolver(solver), DensityIteration(iteration[0]) if iteration else FluidConfig.density_iteration


def operation_name(op) -> str:
    """The kernel of a recorded launch, else the operation's own name (e.g. the neighbour grid's sort)."""
    kernel = getattr(getattr(op, "__self__", None), "kernel", None)
    return kernel.key if kernel is not None else getattr(op, "__qualname__", type(op).__name__)


class OperationTimer:
    """A :attr:`FluidSolver.operation_hook` that times each operation by the calling thread's CPU time (ms, by
    :func:`operation_name`): on the CPU a launch runs to completion on that thread before it returns."""

    def __init__(self) -> None:
        self.total: dict[str, float] = defaultdict(float)
        self.count: dict[str, int] = defaultdict(int)

    def __call__(self, op) -> None:
        start = time.thread_time()
        op()
        name = operation_name(op)
        self.total[name] += 1e3 * (time.thread_time() - start)
        self.count[name] += 1


def profile_case(
    dim: int, n: int, solver: PressureSolver, iteration: DensityIteration, device: str, steps: int, top: int, pair_layout: str | None = None,
) -> list[str]:
    """The case's lines of the report: a heading, the wall and the timed totals, the table of the top activities
    (on CUDA the device's activities, timed by warp; on the CPU each operation, timed by the thread's CPU time).
    ``pair_layout``: a key of :data:`PAIR_LAYOUTS` (None: the device's own layout)."""
    layout = None if pair_layout is None else replace(layout_for(wp.get_device(device)), **PAIR_LAYOUTS[pair_layout])
    fluid, interval = resting_block(n, dim, device, steps, solver, graphs=False, iteration=iteration, layout=layout)
    fluid.advance(interval)  # compiles, settles
    cuda = fluid.device.is_cuda
    timer = OperationTimer()
    if cuda:
        wp.timing_begin(cuda_filter=wp.TIMING_ALL)
    else:
        fluid.operation_hook = timer
    start = time.perf_counter()
    report = fluid.advance(interval)
    wp.synchronize_device(fluid.device)
    wall_ms = 1e3 * (time.perf_counter() - start)
    fluid.operation_hook = None
    for r in wp.timing_end() if cuda else []:
        timer.total[r.name] += r.elapsed
        timer.count[r.name] += 1
    total, count = timer.total, timer.count
    timed_ms, timed_count = sum(total.values()), sum(count.values())
    what = "device activities" if cuda else "operations (each timed by the thread's CPU time)"
    sub = report.substeps
    layout_name = "" if pair_layout is None else f", pair tables in {pair_layout}"
    lines = [
        f"## {dim}-D, {fluid.n_particles} particles, {solver.value}{f' ({iteration.value})' if solver is PressureSolver.DFSPH else ''}, {fluid.device}{layout_name}",
        "",
        f"{sub} substeps: wall {wall_ms:.2f} ms ({wall_ms / sub:.3f} ms a substep), {what} {timed_ms:.2f} ms "
        f"({timed_ms / sub:.3f} ms a substep, {timed_count} of them, {timed_count / sub:.0f} a substep).",
        "",
    ]
    if total:
        lines += [f"| {'activity' if cuda else 'operation'} | count | ms per substep | share of the timed total |", "|---|---|---|---|"]
        for name in sorted(total, key=total.get, reverse=True)[:top]:
            lines.append(f"| {name} | {count[name]} | {total[name] / sub:.4f} | {100 * total[name] / timed_ms:.1f} % |")
        lines.append("")
    return lines


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--device", default="cuda")
    p.add_argument("--cases", nargs="*", default=DEFAULT_CASES, help="dim:particles:solver[:iteration], one profile each")
    p.add_argument("--steps", type=int, default=20, help="WCSPH substeps per interval (the benchmark's)")
    p.add_argument("--top", type=int, default=12, help="activities listed per case")
    p.add_argument("--pair-layouts", nargs="*", choices=sorted(PAIR_LAYOUTS), help="profile each case under each of these pair-table layouts "
                   "(default: the device's own only)")
    p.add_argument("--out", type=Path, default=Path("recordings") / "kernel_profile")
    args = p.parse_args(argv)
    device = str(resolve_device(args.device))
    lines = [f"# Kernel profile ({device})", ""]
    for case in args.cases:
        for pair_layout in args.pair_layouts or [None]:
            case_lines = profile_case(*parse_case(case), device, args.steps, args.top, pair_layout)
            print("\n".join(case_lines), flush=True)
            lines += case_lines
    write_text_atomic(args.out / "kernel_profile.md", "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
