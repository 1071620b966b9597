"""``cosim pour [SCENE.toml]``: simulate a complete robot pour and write its outputs.

Without a scene file the embedded default scene runs (``cosim scene --dump`` prints it). Outputs go to a new run
folder under ``recordings/`` named after the scene file (``cosim pour my_cell.toml``: recordings/<UTC time>-my_cell,
unless the scene sets ``name``; the default scene, the setup of Camporredondo et al. (2019) it starts
from: <UTC time>-seed-pour) or to ``--out DIR``: pour.rrd (Rerun;
``cosim view RUN`` opens it), trajectory.csv, trajectory.json and trajectory.mcap (jerk-limited joint trajectories for
the real arms; the MCAP for ROS 2, docs/ros2.md), summary.json.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

from typing import TYPE_CHECKING

from cosim.checks import check_device
from cosim.coupling.settings import CouplingSettings
from cosim.fluid.config import FluidConfig
from declared_settings.setting import declared

if TYPE_CHECKING:
    from cosim.pour_scene import PourScene


def register(subparsers, summary: str) -> None:
    p = subparsers.add_parser("pour", help=summary, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", nargs="?", type=Path, help="scene TOML file (default: the embedded default scene)")
    p.add_argument("--out", type=Path, help="output folder (must not exist or be empty; default: a new folder under recordings/)")
    p.add_argument("--device", help="cpu or cuda[:N] (overrides the scene)")
    p.add_argument("--threads", type=int, help="CPU threads the liquid solver splits each substep over, 0: one per core (overrides fluid.cpu_threads)")
    p.add_argument("--dim", type=int, help="2: 2-D, 3: 3-D liquid (overrides fluid.dim)")
    p.add_argument("--duration", type=float, help="longest simulated time, s (overrides coupling.max_duration)")
    p.add_argument("--no-log", action="store_true", help="skip the Rerun recording")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--yes", action="store_true", help="run even when the run is estimated at over an hour of wall time")
    p.set_defaults(func=run)


def scene_from_args(args) -> PourScene:
    """The scene file's (or the default) scene with the command line's overrides. The options are checked before the
    scene is loaded: a bad value is refused without importing the scene's libraries."""
    device = check_device("--device", args.device) if args.device is not None else None
    threads = declared(FluidConfig, "cpu_threads").check("--threads", args.threads) if args.threads is not None else None
    dim = declared(FluidConfig, "dim").check("--dim", args.dim) if args.dim is not None else None
    duration = declared(CouplingSettings, "max_duration").check("--duration", args.duration) if args.duration is not None else None
    from cosim.pour_scene import PourScene, load_scene

    scene = load_scene(args.scene).named_after(args.scene) if args.scene is not None else PourScene()
    if device is not None:
        scene = replace(scene, device=device)
    if threads is not None:
        scene = replace(scene, fluid=replace(scene.fluid, cpu_threads=threads))
    if dim is not None:
        scene = replace(scene, fluid=replace(scene.fluid, dim=dim))
    if duration is not None:
        scene = replace(scene, coupling=replace(scene.coupling, max_duration=duration))
    if args.no_log:
        scene = replace(scene, logging=replace(scene.logging, enabled=False))
    return scene


def run(args) -> int:
    scene = scene_from_args(args)  # a bad scene is refused before the simulation's libraries load
    from cosim.pour_run import run_pour
    from cosim.validation.mesh_plant import identified_plant

    def identify(pourer, fill, cfg):
        print(f"identifying the slosh plant of {pourer.name} ({pourer.mesh.source}: no closed form) from the liquid ...",
              file=sys.stderr, flush=True)
        return identified_plant(pourer, fill, cfg.dim, cfg.spacing, cfg.pressure_solver, scene.device)

    folder, summary = run_pour(scene, args.out, progress=not args.quiet, long_run_ok=args.yes, identify_plant=identify)
    initial = summary["initial_volume"]
    ml = 1e6
    print(f"wrote {folder}: {', '.join(summary['outputs'])}")
    print(
        f"poured {summary['poured_volume'] * ml:.0f} of {initial * ml:.0f} mL, {summary['volume_left_in_pourer'] * ml:.0f} mL "
        f"left in the pourer; caught {summary['caught_volume'] * ml:.0f} mL, spilled {summary['spilled_volume'] * ml:.0f} mL "
        f"({100 * summary['spilled_fraction_of_poured']:.1f} % of poured); "
        f"{'pour done' if summary['pour_done'] else 'pour NOT finished within the duration'}"
    )
    if summary["target_volume"] is not None:
        print(f"partial pour: target {summary['target_volume'] * ml:.1f} mL, poured {summary['target_error'] * ml:+.1f} mL "
              f"({100 * summary['target_relative_error']:+.1f} %) off it")
    phases = " -> ".join(f"{p['phase']} {p['start']:.2f}-{p['end']:.2f}s" for p in summary["phases"])
    print(f"phases: {phases}")
    threads = f" ({summary['fluid_threads']} thread{'s' if summary['fluid_threads'] > 1 else ''}{_one_thread_note(summary)})" if summary["device"] == "cpu" else ""
    print(f"simulated {summary['sim_time']:.2f} s in {summary['wall_time']:.1f} s wall (real-time factor {summary['real_time_factor']:.3f}), "
          f"{summary['particles']} particles, {summary['device']}{threads}", file=sys.stdout)
    return 0


def _one_thread_note(summary: dict) -> str:
    """How much of the liquid ran on one thread although it had more (its threads stalled each other on busy
    cores, ``cosim.fluid.lane_choice``); empty when none did."""
    if summary["fluid_substeps_one_thread"] == 0:
        return ""
    share = summary["fluid_substeps_one_thread"] / summary["sph_steps"]
    return f", {100 * share:.3g} % of the substeps on one thread, where it was the faster (busy cores) or was timed"
