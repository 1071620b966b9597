"""Replay a pour's recorded vessel targets through the task-space pose filter and smoothing, without the liquid.

    python -m cosim.bench.pose_filter_replay RUN [RUN ...] [--rest-to-rest]

Reads ``RUN/series.csv`` (the controller's pourer targets ``target_dx``, ``target_dz``, ``target_theta`` and the
phase, every control period) and passes them through :class:`cosim.coupling.pose_filter.PoseFilter` and
:class:`cosim.coupling.pose_filter.PoseSmoother` as the coupling loop does (the slosh damping's command passed
through, the slosh damping undelayed, CFS tracked). The filters are pure functions of the targets, so with the
code that ran the pour the replay gives the recorded ``smoothed_theta`` exactly (printed as a check) in a pour without
slosh induction (the coupling feeds the filter the excitation ahead of the recorded command: the replay differs from
there on); with other filter code it shows what that code would have made of the same targets. The controller does
not see the change (the targets are the recorded ones), so this measures the filter alone. ``--rest-to-rest``: the
jerk-limited filter in CFS too (each target approached as one to stop at), the filter before tracking.

Prints, over CFS from :data:`SETTLE` after its start to its end: the tilt's delay behind the command
(least-squares fit, :func:`controllers.motion.fitted_delay`) after the filter and after the smoothing, and per
coordinate the smoothed path's acceleration content above 10 Hz (m/s^2 or rad/s^2, from second differences at the
control rate) and its jerk sign changes per second (:mod:`cosim.trajectory.smoothness`).
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np

from controllers.measurement import Phase
from controllers.motion import fitted_delay
from cosim.coupling.loop import TRACKED, UNDELAYED
from cosim.coupling.pose_filter import PoseFilter, PoseFilterLimits, PoseSmoother
from cosim.robots.planar import PlanarPose
from cosim.trajectory.smoothness import acceleration_rms_above, jerk_sign_changes

COORDINATES = ("dx", "dz", "theta")
SETTLE = 0.5  # s after CFS starts (the entry's transient) before the statistics
MAX_DELAY = 0.3  # s, the delays fitted
DELAY_RESOLUTION = 0.001  # s


def replay(series: Path, rest_to_rest: bool = False) -> dict[str, object]:
    """The replay of one ``series.csv``: recorded times, phases, command, the filter's and the smoothed paths."""
    rows = list(csv.DictReader(series.open()))
    period = float(rows[1]["t"]) - float(rows[0]["t"])
    pose_filter = PoseFilter("pourer_pose", COORDINATES, PoseFilterLimits(), period)
    smoother = PoseSmoother(COORDINATES, period)
    limited_path, smoothed_path = [], []
    for row in rows:
        phase = Phase(row["phase"])
        target = PlanarPose(float(row["target_dx"]), float(row["target_dz"]), float(row["target_theta"]))
        limited = pose_filter(target, pass_through=phase is Phase.SIM_DAMP, track=phase in TRACKED and not rest_to_rest)
        passed = pose_filter.passing
        smoothed = smoother(limited, passing=passed or phase in UNDELAYED, source="command" if passed else "limited")
        limited_path.append([getattr(limited, c) for c in COORDINATES])
        smoothed_path.append([getattr(smoothed, c) for c in COORDINATES])
    return {
        "period": period,
        "t": np.array([float(r["t"]) for r in rows]),
        "tracked": np.array([Phase(r["phase"]) in TRACKED for r in rows]),
        "command": np.array([float(r["target_theta"]) for r in rows]),
        "recorded": np.array([float(r["smoothed_theta"]) for r in rows]),
        "limited": np.array(limited_path),
        "smoothed": np.array(smoothed_path),
    }


def report(run: Path, rest_to_rest: bool) -> str:
    r = replay(run / "series.csv", rest_to_rest)
    t, h, tracked = r["t"], r["period"], r["tracked"]
    lines = [f"{run}: replay - recorded smoothed_theta, max {np.max(np.abs(r['smoothed'][:, 2] - r['recorded'])):.3g} rad"]
    if not np.any(tracked):
        return lines[0] + " (no CFS)"
    start, end = t[tracked][0] + SETTLE, t[tracked][-1]
    window = (t >= start) & (t <= end)
    delays = [fitted_delay(t[window], r["command"][window], path[window, 2], MAX_DELAY, DELAY_RESOLUTION) for path in (r["limited"], r["smoothed"])]
    lines.append(f"  CFS {start:.2f}-{end:.2f} s: tilt behind the command {1e3 * delays[1]:.0f} ms ({1e3 * delays[0]:.0f} ms after the filter, before the smoothing)")
    acceleration = np.diff(r["smoothed"][window], 2, axis=0) / h**2
    content = acceleration_rms_above(acceleration, 1.0 / h)
    changes = jerk_sign_changes(np.diff(acceleration, axis=0) / h) / (end - start)
    lines.append("  " + ", ".join(f"{c} {a:.4f} /s^2 above 10 Hz, {n:.1f} jerk sign changes/s" for c, a, n in zip(COORDINATES, content, changes)))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs="+", type=Path, help="run folders holding series.csv")
    parser.add_argument("--rest-to-rest", action="store_true", help="the jerk-limited filter in CFS too (no tracking)")
    args = parser.parse_args(argv)
    for run in args.runs:
        print(report(run, args.rest_to_rest))


if __name__ == "__main__":
    main()
