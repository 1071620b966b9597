"""Benchmark inverse kinematics over the pour workspace: accuracy and time per solve.

``python -m cosim.bench.ik [--json] [--model SCENE]``

Workspace (targets relative to the vessels' home poses, :mod:`cosim.robots.planar`): the pourer tilted
0..120 deg (every :data:`TILT_STEP_DEG`) about its bottom middle and about its lip; the catcher translated
-0.15..+0.15 m along world x (every :data:`CATCHER_STEP_M`). Each target is solved twice: "cold", seeded with
the home posture, and "warm", seeded with the previous target's solution along the sweep (how a controller
streaming targets calls it). The error of every solution is re-measured independently by forward kinematics
(``mj_kinematics`` on a separate MjData): position of the vessel frame origin (m) and rotation angle (deg) to the
target. Times are wall-clock per ``solve_vessel_target`` call (``time.perf_counter``), single thread.

Acceptance: every target within :data:`MAX_POSITION_ERROR_M` and :data:`MAX_ROTATION_ERROR_DEG`, median
time per solve <= :data:`MAX_MEDIAN_SOLVE_S`.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time

import mujoco
import numpy as np

from cosim.errors import InputError
from cosim.robots.ik import rotation_error
from cosim.frames import quat_wxyz_to_matrix
from cosim.robots.planar import PlanarPose, tilt_about_pivot
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole

TILT_STEP_DEG = 2.0
MAX_TILT_DEG = 120.0
CATCHER_RANGE_M = 0.15
CATCHER_STEP_M = 0.01
# Acceptance thresholds: m, deg, s.
MAX_POSITION_ERROR_M = 1e-3
MAX_ROTATION_ERROR_DEG = 0.1
MAX_MEDIAN_SOLVE_S = 2e-3


def workspace(scene: RobotScene) -> list[tuple[str, ArmRole, list[PlanarPose]]]:
    """The benchmark's target sweeps: (label, arm, ordered targets)."""
    pourer = scene.arms[ArmRole.POUR]
    tilts = np.radians(np.arange(0.0, MAX_TILT_DEG + 1e-9, TILT_STEP_DEG))
    sweeps = []
    for label, pivot in (("pourer tilt about bottom", np.zeros(3)), ("pourer tilt about lip", pourer.vessel.lip_local)):
        sweeps.append((label, ArmRole.POUR, [tilt_about_pivot(pourer.home_quat, pivot, th) for th in tilts]))
    offsets = np.arange(-CATCHER_RANGE_M, CATCHER_RANGE_M + 1e-9, CATCHER_STEP_M)
    sweeps.append(("catcher translation", ArmRole.CATCH, [PlanarPose(dx=float(dx)) for dx in offsets]))
    return sweeps


def run_benchmark(scene: RobotScene) -> dict:
    """Solve every workspace target cold and warm; return counts, worst errors and time statistics."""
    check = mujoco.MjData(scene.model)
    check.qpos[:] = scene.data.qpos
    results = {"cold": {"times": [], "pos": [], "rot": []}, "warm": {"times": [], "pos": [], "rot": []}}
    failures = []
    for label, role, targets in workspace(scene):
        arm = scene.arms[role]
        previous = arm.home_q
        for pose in targets:
            target_pos, target_quat = scene.vessel_target(role, pose)
            for mode in ("cold", "warm"):
                seed = arm.home_q if mode == "cold" else previous
                start = time.perf_counter()
                try:
                    q = scene.solve_vessel_target(role, pose, seed)
                except InputError as exc:
                    failures.append(f"{label} ({mode}): {exc}")
                    continue
                results[mode]["times"].append(time.perf_counter() - start)
                check.qpos[arm.qpos_adr] = q
                mujoco.mj_kinematics(scene.model, check)
                results[mode]["pos"].append(float(np.linalg.norm(check.site_xpos[arm.frame_site] - target_pos)))
                rot = rotation_error(quat_wxyz_to_matrix(target_quat), check.site_xmat[arm.frame_site].reshape(3, 3))
                results[mode]["rot"].append(math.degrees(float(np.linalg.norm(rot))))
                if mode == "warm":
                    previous = q
    summary = {"targets": sum(len(t) for _, _, t in workspace(scene)), "failures": failures}
    for mode, r in results.items():
        times = np.array(r["times"])
        summary[mode] = {
            "solves": int(times.size),
            "max_position_error_m": max(r["pos"], default=math.nan),
            "max_rotation_error_deg": max(r["rot"], default=math.nan),
            "median_time_s": float(np.median(times)) if times.size else math.nan,
            "p95_time_s": float(np.percentile(times, 95)) if times.size else math.nan,
            "max_time_s": float(times.max()) if times.size else math.nan,
        }
        summary[mode]["pass"] = bool(
            not failures
            and summary[mode]["max_position_error_m"] <= MAX_POSITION_ERROR_M
            and summary[mode]["max_rotation_error_deg"] <= MAX_ROTATION_ERROR_DEG
            and summary[mode]["median_time_s"] <= MAX_MEDIAN_SOLVE_S
        )
    return summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Benchmark IK over the pour workspace.")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.add_argument("--model", default=None, help="scene MJCF (default: the project's scene)")
    args = parser.parse_args(argv)
    try:
        summary = run_benchmark(RobotScene.load(args.model))
    except InputError as exc:
        print(f"ik: error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{summary['targets']} targets, {len(summary['failures'])} failures")
        for failure in summary["failures"]:
            print(f"  {failure}")
        for mode in ("cold", "warm"):
            s = summary[mode]
            print(
                f"{mode:>4}: max error {s['max_position_error_m'] * 1000:.2e} mm, {s['max_rotation_error_deg']:.2e} deg; "
                f"time per solve median {s['median_time_s'] * 1000:.3f} ms, p95 {s['p95_time_s'] * 1000:.3f} ms, "
                f"max {s['max_time_s'] * 1000:.3f} ms; {'PASS' if s['pass'] else 'FAIL'}"
            )
    return 0 if all(summary[m]["pass"] for m in ("cold", "warm")) else 1


if __name__ == "__main__":
    raise SystemExit(main())
