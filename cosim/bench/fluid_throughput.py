"""Fluid throughput benchmark: particle-steps per second of the SPH step, side by side with warp's bundled
``example_sph`` at the same particle count (a benchmark, not a test).

    python -m cosim.bench.fluid_throughput [--device cpu|cuda] [--counts2d 1000 4000 16000] [--counts3d 4000 16000 62500]
                                    [--solvers wcsph dfsph] [--threads 0 1] [--repeats 3] [--no-graphs]
                                    [--out docs/benchmarks.md]

Ours: a resting box of liquid in a tank (the hydrostatic case), every stage of a substep (walls, neighbour sort,
reorder, then the pressure solver's stages, integration, wrench reduction), for each pressure solver. Besides
particle-steps/s (cost per substep) it reports simulated seconds per wall-clock second over the same interval,
the comparison that matters between solvers whose time steps differ (WCSPH: acoustic CFL; DFSPH: flow CFL and the
force criterion, with its iterations per substep). On the CPU each thread count asked for is a row of its own
(``FluidConfig.cpu_threads``; 0: one per core, at most one per 200 particles), the threads column the number used.
``example_sph``: warp's own
3-D toy (Mueller 2003 kernels on ``wp.HashGrid``, a handful of neighbours per particle), re-sized to the same
count by reallocating its particle arrays with its own initialisation kernel. Since the two differ in neighbours
per particle, each row also gives the mean neighbours (liquid particles within the kernel's support, counted on the
final positions by :func:`mean_neighbours`; ours leave out the wall particles, which the liquid at the tank's
walls also sums over) and the pair interactions per second, particle-steps/s times that mean. Both are timed after a warm-up
step (kernel compilation excluded); the median of ``repeats`` timed batches is reported. Appends a dated section
to the Markdown file with the machine and versions.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import math
import platform
import statistics
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import warp as wp

from cosim.fluid.config import DensityIteration, FluidConfig, PressureSolver
from cosim.fluid.device_layout import DeviceLayout
from cosim.fluid.runtime import resolve_device
from cosim.fluid.seeding import liquid_block
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.vessel import VesselSpec

TANK_ASPECT = 1.0  # the liquid block is as tall as it is wide


def resting_block(
    n: int, dim: int, device: str, steps: int, solver: PressureSolver, graphs: bool = True, threads: int = 0,
    iteration: DensityIteration = FluidConfig.density_iteration, layout: DeviceLayout | None = None,
) -> tuple[FluidSolver, float]:
    """The benchmark's liquid: a resting block of ~n particles in a tank, and the interval (s) of ``steps`` WCSPH
    substeps that every solver is timed over (``iteration``: DFSPH's density iteration; ``layout``: the solver's
    :class:`DeviceLayout`, None for the device's own)."""
    width = 0.2
    depth = width if dim == 3 else 0.1
    cells = n ** (1.0 / dim)
    dx = width / cells
    tank = VesselSpec(name="tank", inner_width=width, inner_depth=depth, inner_height=1.5 * width)
    m = 0.1 * width
    cfg = FluidConfig(
        dim=dim, spacing=dx, max_expected_speed=2 * math.sqrt(9.81 * width), pressure_solver=solver, cpu_threads=threads, density_iteration=iteration,
        domain_min=(-0.5 * width - m, -0.5 * depth - m, -m), domain_max=(0.5 * width + m, 0.5 * depth + m, 1.5 * width + m),
    )
    block = liquid_block((-0.5 * width, -0.5 * depth, 0.0), (0.5 * width, 0.5 * depth, width * TANK_ASPECT), cfg)
    fluid = FluidSolver(cfg, [tank], [Pose()], block, device=device, graphs=graphs, layout=layout)
    return fluid, steps * cfg.cfl * cfg.smoothing_length / cfg.sound_speed * 0.999


def mean_neighbours(positions: np.ndarray, radius: float) -> float:
    """Mean number of other points closer than ``radius`` (m) to each point of ``positions`` (n, dim), the
    kernel's support (points at exactly ``radius`` left out, as the neighbour walk does)."""
    from scipy.spatial import cKDTree

    tree = cKDTree(positions)
    within = tree.count_neighbors(tree, radius * (1.0 - 1e-6))  # ordered pairs, each point with itself included
    return (float(within) - len(positions)) / len(positions)


def solver_throughput(
    n: int, dim: int, device: str, steps: int, repeats: int, solver: PressureSolver, graphs: bool, threads: int, iteration: DensityIteration,
) -> tuple[float, float, int, float, int, float]:
    """(median particle-steps/s, median simulated s per wall s, actual particle count, mean substep dt in s, threads,
    mean liquid neighbours at the end) of our
    solver on a resting liquid block of ~n particles, timed over intervals of ``steps`` WCSPH substeps after a
    settling interval of the same length (kernel compilation, DFSPH's cold start and the CUDA graph capture
    excluded)."""
    fluid, interval = resting_block(n, dim, device, steps, solver, graphs, threads, iteration)
    fluid.advance(interval)  # warm-up: compiles, records, settles
    rates, speeds, dts = [], [], []
    for _ in range(repeats):
        wp.synchronize_device(fluid.device)
        start = time.perf_counter()
        fluid.advance(interval)
        wp.synchronize_device(fluid.device)
        wall = time.perf_counter() - start
        rates.append(fluid.n_particles * fluid.last_report.substeps / wall)
        speeds.append(interval / wall)
        dts.append(fluid.last_report.dt)
    x = fluid.positions()[:, [0, 2]] if dim == 2 else fluid.positions()
    neighbours = mean_neighbours(x, fluid.config.support_radius)
    return statistics.median(rates), statistics.median(speeds), fluid.n_particles, statistics.mean(dts), fluid.lanes.count, neighbours


def example_sph_throughput(n: int, device: str, steps: int, repeats: int) -> tuple[float, float]:
    """(median particle-steps/s, mean neighbours at the end) of warp's bundled example_sph re-sized to n particles
    (its kernels' support is its smoothing length)."""
    from warp.examples.core import example_sph

    with wp.ScopedDevice(device):
        ex = example_sph.Example(stage_path=None)
        h = (ex.height * (ex.width / 4.0) * (ex.height / 4.0) / n) ** (1.0 / 3.0)
        scale = h / ex.smoothing_length
        ex.smoothing_length = h
        ex.n = n
        ex.particle_mass *= scale**3
        ex.dt *= scale
        ex.density_normalization = (315.0 * ex.particle_mass) / (64.0 * np.pi * h**9)
        ex.pressure_normalization = -(45.0 * ex.particle_mass) / (np.pi * h**6)
        ex.viscous_normalization = (45.0 * ex.dynamic_visc * ex.particle_mass) / (np.pi * h**6)
        ex.x, ex.v, ex.rho, ex.a = (wp.empty(n, dtype=wp.vec3), wp.zeros(n, dtype=wp.vec3), wp.zeros(n, dtype=float), wp.zeros(n, dtype=wp.vec3))
        wp.launch(example_sph.initialize_particles, dim=n, inputs=[ex.x, h, ex.width, ex.height, ex.length])
        grid_size = int(ex.height / (4.0 * h))
        ex.grid = wp.HashGrid(grid_size, grid_size, grid_size)
        ex.sim_step_to_frame_ratio = steps
        wp.config.verbose_warnings = False
        rates = []
        with contextlib.redirect_stdout(io.StringIO()):  # its step prints its own timer's line every call
            ex.step()  # warm-up
            for _ in range(repeats):
                wp.synchronize_device()
                start = time.perf_counter()
                ex.step()
                wp.synchronize_device()
                rates.append(n * steps / (time.perf_counter() - start))
        neighbours = mean_neighbours(ex.x.numpy(), h)
    return statistics.median(rates), neighbours


def machine_description() -> str:
    """The CPU's model name, its logical core count and the operating system, for a benchmark's header."""
    cpu = platform.processor() or "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    import os

    return f"{cpu}, {os.cpu_count()} logical cores, {platform.system()} {platform.release()}"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--device", default="cpu")
    p.add_argument("--counts2d", type=int, nargs="*", default=[1000, 4000, 16000])
    p.add_argument("--counts3d", type=int, nargs="*", default=[4000, 16000, 62500])
    p.add_argument("--steps", type=int, default=20, help="WCSPH substeps per timed interval (the same simulated interval for every solver)")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--solvers", nargs="*", choices=[s.value for s in PressureSolver], default=[s.value for s in PressureSolver])
    p.add_argument("--threads", type=int, nargs="*", default=[0], help="CPU threads of the solver, one row each (0: one per core)")
    p.add_argument("--density-iteration", choices=[i.value for i in DensityIteration], default=FluidConfig.density_iteration.value,
                   help="DFSPH's density iteration (jacobi: every particle at once, the GPU's choice for large liquids)")
    p.add_argument("--no-graphs", action="store_true", help="run a substep's launches one by one instead of replaying its captured graph")
    p.add_argument("--out", type=Path, default=None, help="append the table to this Markdown file")
    args = p.parse_args(argv)
    device = resolve_device(args.device)
    rows = []
    for dim, counts in ((2, args.counts2d), (3, args.counts3d)):
        for n in counts:
            theirs, their_neighbours = float("nan"), float("nan")
            for name in args.solvers:
                for threads in args.threads:
                    ours, sim_rate, actual, dt, used, neighbours = solver_throughput(
                        n, dim, str(device), args.steps, args.repeats, PressureSolver(name), not args.no_graphs, threads, DensityIteration(args.density_iteration),
                    )
                    if dim == 3 and math.isnan(theirs):
                        theirs, their_neighbours = example_sph_throughput(actual, str(device), args.steps, args.repeats)
                    rows.append((dim, actual, name, used, ours, sim_rate, dt, neighbours, theirs, their_neighbours))
                    print(f"{dim}-D {actual:>8d} particles {name} {used} threads: {ours / 1e6:8.3f} M particle-steps/s, {neighbours:.1f} neighbours, "
                          f"{ours * neighbours / 1e9:8.3f} G pairs/s, dt {dt * 1e6:8.1f} us, {sim_rate:8.4f} simulated s per wall s"
                          + (f"   example_sph {theirs / 1e6:8.3f} M, {their_neighbours:.1f} neighbours" if dim == 3 else ""), flush=True)
    table = ["| dim | particles | solver | threads | M particle-steps/s | steps/s | neighbours | G pair interactions/s | substep dt (us) | simulated s / wall s "
             "| warp example_sph: M particle-steps/s | its neighbours | its G pair interactions/s |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for dim, n, name, used, ours, sim_rate, dt, neighbours, theirs, their_neighbours in rows:
        ex = f"{theirs / 1e6:.3f} | {their_neighbours:.1f} | {theirs * their_neighbours / 1e9:.3f}" if not math.isnan(theirs) else "- (3-D only) | - | -"
        table.append(f"| {dim}-D | {n} | {name} | {used} | {ours / 1e6:.3f} | {ours / n:.0f} | {neighbours:.1f} | {ours * neighbours / 1e9:.3f} | {dt * 1e6:.1f} | {sim_rate:.4f} | {ex} |")
    header = (
        f"\n## Fluid step throughput, {device} ({datetime.now(timezone.utc):%Y-%m-%d})\n\n"
        f"Machine: {machine_description()}. Versions: Python {platform.python_version()}, warp {wp.__version__}, numpy {np.__version__}.\n"
        f"Command: `python -m cosim.bench.fluid_throughput --device {args.device} --counts2d {' '.join(map(str, args.counts2d))} "
        f"--counts3d {' '.join(map(str, args.counts3d))} --solvers {' '.join(args.solvers)} --threads {' '.join(map(str, args.threads))} "
        f"--steps {args.steps} --repeats {args.repeats} --density-iteration {args.density_iteration}"
        f"{' --no-graphs' if args.no_graphs else ''}`. "
        f"Median of {args.repeats} intervals of {args.steps} WCSPH substeps' simulated time after a settling interval; one step "
        "is the full substep (walls, neighbour sort and reorder, the pressure solver's stages, integration, wrench "
        "reduction; DFSPH's includes its iterations); simulated s / wall s compares the solvers at equal simulated time; "
        "example_sph is warp's bundled toy (Mueller 2003 kernels, few neighbours) re-sized to the same count.\n\n"
    )
    text = header + "\n".join(table) + "\n"
    print(text)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        with args.out.open("a") as f:
            f.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
