"""The checked trajectory files of a scripted pour, written without a simulation.

    python -m cosim.tools.scripted_pour --out DIR [--duration S] [--tilt-deg DEG] [--catcher-dx M] [--sample-rate HZ]

writes ``DIR/trajectory.csv``, ``.json`` and ``.mcap`` of a smooth pour (:mod:`cosim.trajectory.pour_motion`: tilt
about the lip and back, the catcher moving along x) generated as the coupling does
(:func:`cosim.trajectory.scripted.generate_scripted`) and prints the lips' deviation from the scripted path;
``cosim replay DIR/trajectory.csv`` then measures how the servos track it.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from cosim.errors import InputError, SimulationError
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.deviation import path_deviation
from cosim.trajectory.driver_names import JointPrefix, driver_joint_names
from cosim.trajectory.export import write_trajectory_files
from cosim.trajectory.pour_motion import Pivot, PourMotionSpec
from cosim.trajectory.sampling import DEFAULT_SAMPLE_RATE_HZ
from cosim.trajectory.scripted import generate_scripted, pour_path, pour_poses


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Write the checked trajectory CSV, JSON and MCAP of a scripted pour.")
    parser.add_argument("--out", required=True, help="folder for trajectory.csv, trajectory.json and trajectory.mcap")
    parser.add_argument("--duration", type=float, default=PourMotionSpec.duration, help=f"s (default {PourMotionSpec.duration:g})")
    parser.add_argument("--tilt-deg", type=float, default=100.0, help="peak tilt about the lip, deg (default 100)")
    parser.add_argument("--catcher-dx", type=float, default=PourMotionSpec.catcher_dx,
                        help=f"catcher travel at peak, m (default {PourMotionSpec.catcher_dx:g})")
    parser.add_argument("--sample-rate", type=float, default=DEFAULT_SAMPLE_RATE_HZ, help=f"Hz (default {DEFAULT_SAMPLE_RATE_HZ:g})")
    args = parser.parse_args(argv)
    try:
        scene = RobotScene.load()
        spec = PourMotionSpec(args.duration, math.radians(args.tilt_deg), Pivot.LIP, args.catcher_dx)
        run = generate_scripted(scene, pour_poses(scene, spec), sample_rate_hz=args.sample_rate)
        out = Path(args.out)
        write_trajectory_files(
            run.trajectory, run.limits, run.sample_rate_hz, driver_joint_names(scene, JointPrefix()),
            out / "trajectory.csv", out / "trajectory.json", out / "trajectory.mcap",
        )
    except (InputError, SimulationError) as exc:
        print(f"scripted: error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {out}/trajectory.csv, .json and .mcap: {run.trajectory.time.size} samples, {run.trajectory.duration:.3f} s")
    paths = pour_path(scene, spec)
    for role in ArmRole:
        deviation = path_deviation(scene, role, run.trajectory, paths[role])
        print(
            f"{role.value}: lip deviation from the scripted path: max {deviation.max() * 1e3:.4f} mm, "
            f"RMS {np.sqrt(np.mean(deviation**2)) * 1e3:.4f} mm"
        )
    for role in ArmRole:
        print(
            f"{role.value}: targets missed by the arm: {run.late_targets[role]}, largest joint distance to a target on "
            f"arrival: {run.max_target_error[role]:.2e} rad"
        )
    print(f"targets clamped to the joint range: {sum(run.clamped_targets.values())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
