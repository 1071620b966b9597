"""A smooth two-arm pour motion written as a trajectory CSV (:func:`cosim.trajectory.pour_motion.plan_pour_trajectory`).

    python -m cosim.tools.pour_motion --out pour.csv [--duration 10] [--tilt-deg 120] [--pivot lip|bottom]
                                      [--catcher-dx 0.15] [--model SCENE]

``cosim replay pour.csv`` then measures how the servos track it.
"""

from __future__ import annotations

import argparse
import math
import sys

from cosim.errors import InputError
from cosim.robots.scene import RobotScene
from cosim.trajectory.csv_file import write_trajectory_csv
from cosim.trajectory.pour_motion import Pivot, PourMotionSpec, plan_pour_trajectory


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Write a smooth two-arm pour motion as a trajectory CSV.")
    parser.add_argument("--out", required=True, help="CSV file to write")
    parser.add_argument("--duration", type=float, default=10.0, help="s (default 10)")
    parser.add_argument("--tilt-deg", type=float, default=120.0, help="peak tilt, deg (default 120)")
    parser.add_argument("--pivot", choices=[p.value for p in Pivot], default=Pivot.LIP.value)
    parser.add_argument("--catcher-dx", type=float, default=0.15, help="catcher travel at peak, m (default 0.15)")
    parser.add_argument("--model", default=None, help="scene MJCF (default: the project's scene)")
    args = parser.parse_args(argv)
    try:
        spec = PourMotionSpec(args.duration, math.radians(args.tilt_deg), Pivot(args.pivot), args.catcher_dx)
        trajectory = plan_pour_trajectory(RobotScene.load(args.model), spec)
        write_trajectory_csv(args.out, trajectory)
    except InputError as exc:
        print(f"pour_motion: error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {args.out}: {trajectory.time.size} samples, {trajectory.duration:.2f} s, {len(trajectory.joint_names)} joints")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
