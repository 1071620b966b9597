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
    parser.add_argument("--duration", type=float, help=f"s (default {PourMotionSpec.duration:g})")
    parser.add_argument("--tilt-deg", type=float, help=f"peak tilt, deg (default {math.degrees(PourMotionSpec.max_tilt):g})")
    parser.add_argument("--pivot", choices=[p.value for p in Pivot], help=f"(default {PourMotionSpec.pivot.value})")
    parser.add_argument("--catcher-dx", type=float, help=f"catcher travel at peak, m (default {PourMotionSpec.catcher_dx:g})")
    parser.add_argument("--model", default=None, help="scene MJCF (default: the project's scene)")
    args = parser.parse_args(argv)
    given = {"duration": args.duration, "max_tilt": None if args.tilt_deg is None else math.radians(args.tilt_deg),
             "pivot": args.pivot, "catcher_dx": args.catcher_dx}
    try:
        spec = PourMotionSpec(**{k: v for k, v in given.items() if v is not None})
        trajectory = plan_pour_trajectory(RobotScene.load(args.model), spec)
        write_trajectory_csv(args.out, trajectory)
    except InputError as exc:
        print(f"pour_motion: error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {args.out}: {trajectory.time.size} samples, {trajectory.duration:.2f} s, {len(trajectory.joint_names)} joints")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
