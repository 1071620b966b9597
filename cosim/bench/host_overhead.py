"""Host cost of the co-simulation loop: the wall time per MuJoCo step that is not the liquid's substeps.

Each 2 ms MuJoCo step of a pour runs the liquid's substeps (device work) and, around them, the host's share: the
pour controller and its IK and trajectory generators (every control period), ``mj_step``, the pose and wrench
exchange, the upload of the walls' motion and the diagnostics read back after the substeps. The host's share does
not shrink with a faster device, so it bounds the real-time factor of every pour: at 2 ms per step and H ms of host
work per step a pour cannot run faster than 2 / H times real time, however fast its liquid is. It must not grow
with the particle count either; a run at two resolutions shows that.

The split is exact: ``CoupledPour.wall_time`` times every step and ``FluidSolver.substep_wall_time`` the substep
loops inside them (on CUDA up to the device's completion), so host = wall - substeps, both from one run.

    python -m cosim.bench.host_overhead [SCENE.toml] [--duration 2] [--across 16 32] [--solver wcsph dfsph]
                                        [--repeats 3] [--device cpu]

Prints one row per (solver, resolution): steps, medians over the repeats of the wall ms per step, the substeps'
share and the host's, and the real-time factor the host alone would allow.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys

from cosim.coupling.loop import CoupledPour
from cosim.coupling.settings import CouplingSettings
from cosim.errors import InputError
from cosim.bench.fluid_throughput import machine_description
from cosim.bench.options import DURATION, REPEATS
from cosim.fluid.config import PressureSolver
from cosim.pour_run import prepare
from cosim.pour_scene import FluidSettings, LoggingSettings, PourScene, load_scene

POUR_WARM_UP = 0.05  # s simulated before a timed pour: compiles the kernels, captures the graphs


@dataclasses.dataclass(frozen=True)
class HostSplit:
    """One timed pour: particles, MuJoCo steps of ``step_s`` seconds, wall seconds of all steps and of the liquid's
    substeps within them."""

    particles: int
    steps: int
    step_s: float
    wall_s: float
    substep_s: float

    @property
    def host_ms_per_step(self) -> float:
        return 1e3 * (self.wall_s - self.substep_s) / self.steps

    @property
    def substep_ms_per_step(self) -> float:
        return 1e3 * self.substep_s / self.steps


def time_steps(pour: CoupledPour, duration: float) -> HostSplit:
    """Step ``pour`` on by ``duration`` simulated seconds and split the wall time of just those steps."""
    steps, wall, substeps = pour.steps, pour.wall_time, pour.fluid.substep_wall_time
    end = pour.time + duration
    while pour.time < end - 1e-12:
        pour.step()
    return HostSplit(pour.fluid.n_particles, pour.steps - steps, pour.dt, pour.wall_time - wall, pour.fluid.substep_wall_time - substeps)


def capture_status(fluid) -> str:
    """How the solver ran its substeps: replayed graphs (CUDA graphs, or warp's CPU operation stream), or
    launches one by one because capture failed (and why)."""
    return fluid.graph_capture_error or "captured"


def warm_pour(device: str, dim: int, across: int, seconds: float, solver: str, iteration: str) -> CoupledPour:
    """The default scene with this liquid (``solver``: pressure solver, ``iteration``: DFSPH's density iteration),
    no recording, stepped through :data:`POUR_WARM_UP` (kernels compiled, graphs captured), with room for
    ``seconds`` more."""
    scene = PourScene(
        device=device, fluid=dataclasses.replace(FluidSettings(), dim=dim, particles_across=across, pressure_solver=solver, density_iteration=iteration),
        coupling=CouplingSettings(max_duration=POUR_WARM_UP + seconds), logging=LoggingSettings(enabled=False),
    )
    pour = prepare(scene)
    time_steps(pour, POUR_WARM_UP)
    return pour


def pour_rate(device: str, dim: int, across: int, seconds: float, solver: str | None = None, iteration: str | None = None) -> dict:
    """``seconds`` of the default scene's pour timed after :func:`warm_pour` (``solver`` None: the default scene's
    pressure solver, ``iteration`` None: its density iteration): real-time factor, SPH substeps, and the wall time
    per MuJoCo step split into the substeps and the rest (ms)."""
    solver = solver or FluidSettings().pressure_solver.value
    iteration = iteration or FluidSettings().density_iteration.value
    pour = warm_pour(device, dim, across, seconds, solver, iteration)
    substeps0 = pour.fluid.step_count
    split = time_steps(pour, seconds)
    return {
        "dim": dim, "across": across, "solver": solver if solver == "wcsph" else f"{solver} ({iteration})", "particles": split.particles,
        "simulated_s": seconds, "wall_s": split.wall_s, "real_time_factor": seconds / split.wall_s,
        "sph_substeps": pour.fluid.step_count - substeps0, "substeps_ms_per_step": split.substep_ms_per_step,
        "host_ms_per_step": split.host_ms_per_step, "graphs": capture_status(pour.fluid),
    }


def time_pour(scene: PourScene, duration: float) -> HostSplit:
    """Run the first ``duration`` simulated seconds of ``scene`` (no recording, no outputs) and split their wall
    time (kernel loading and the graph capture of the first interval included)."""
    return time_steps(prepare(scene), duration)


def scene_variant(base: PourScene, solver: PressureSolver, across: int, device: str) -> PourScene:
    """``base`` with its pressure solver, resolution and device replaced, and logging off."""
    fluid = dataclasses.replace(base.fluid, pressure_solver=solver, particles_across=across)
    logging = dataclasses.replace(base.logging, enabled=False)
    return dataclasses.replace(base, fluid=fluid, logging=logging, device=device)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m cosim.bench.host_overhead", description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", help="scene TOML file (default: the embedded default scene)")
    ap.add_argument("--duration", type=float, default=2.0, help="simulated s per run (default 2)")
    ap.add_argument("--across", type=int, nargs="+", default=[16, 32], help="fluid.particles_across values (default 16 32)")
    ap.add_argument("--solver", nargs="+", default=["wcsph", "dfsph"], choices=[s.value for s in PressureSolver])
    ap.add_argument("--repeats", type=int, default=3, help="runs per row; medians are printed (default 3)")
    ap.add_argument("--device", default="cpu", help="cpu or cuda[:N] (default cpu)")
    args = ap.parse_args(argv)
    try:
        DURATION.check("--duration", args.duration)
        REPEATS.check("--repeats", args.repeats)
        base = load_scene(args.scene) if args.scene else PourScene()
        variants = [scene_variant(base, PressureSolver(s), n, args.device) for s in args.solver for n in args.across]
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"Machine: {machine_description()}. Command: python -m cosim.bench.host_overhead {' '.join(argv if argv is not None else sys.argv[1:])}")
    print(f"{args.duration:g} s of the pour per run, {args.repeats} runs per row; ms per MuJoCo step, medians.\n")
    print("| solver | across | particles | steps | wall ms/step | substeps ms/step | host ms/step | real-time factor the host allows |")
    print("|---|---|---|---|---|---|---|---|")
    for scene in variants:
        runs = [time_pour(scene, args.duration) for _ in range(args.repeats)]
        host = statistics.median(r.host_ms_per_step for r in runs)
        sub = statistics.median(r.substep_ms_per_step for r in runs)
        wall = statistics.median(1e3 * r.wall_s / r.steps for r in runs)
        print(
            f"| {scene.fluid.pressure_solver.value} | {scene.fluid.particles_across} | {runs[0].particles} | {runs[0].steps} | {wall:.3f} | {sub:.3f} | "
            f"{host:.3f} (runs: {', '.join(f'{r.host_ms_per_step:.3f}' for r in runs)}) | {1e3 * runs[0].step_s / host:.2f} |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
