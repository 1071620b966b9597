"""``cosim replay TRAJECTORY.csv [--json] [--tolerance-mm MM] [--model SCENE] [--payload full|empty] [--feedforward ...]``.

Plays a joint trajectory (a CSV file, :mod:`cosim.trajectory.csv_file`) through the arms' position servos in
MuJoCo without liquid (the liquid as a rigid payload, full by default) and reports per-joint tracking error and
the vessel lips' path errors (:mod:`cosim.trajectory.replay`), then a verdict: PASS when every vessel lip stays
within ``--tolerance-mm`` (default 2 mm) of its commanded path and nothing collides, else FAIL with the reasons. The
servos get the inverse dynamics of the commanded motion as feedforward by default, as an arm's model-based
controller does; with gravity compensation only, a PD servo lags its command by about the torque the motion's
acceleration needs over its gain, and a trajectory using the acceleration limit fails by that alone. The exit
status says it, so that a script or CI job can gate on it: 0 pass, 1 fail, 2 bad input (a bad trajectory file,
scene or option: one line). ``--json`` prints a JSON object with ``verdict`` ("pass" or "fail"), ``tolerance_m``, ``failures`` (the reasons),
``max_error_m`` (largest pour-lip position error, m), ``joint_max_error_rad`` (per-joint maxima) and the rest.
"""

from __future__ import annotations

import argparse
import json
import math

from typing import TYPE_CHECKING

from cosim.robots.payload import PayloadMode
from cosim.trajectory.feedforward import DEFAULT_TOLERANCE_M, Feedforward
from declared_settings.setting import argument

if TYPE_CHECKING:
    from cosim.trajectory.replay import ReplayReport

TOLERANCE_MM = argument("replay", "Largest lip path error that passes.", "mm", 0.0, 1000.0, lo_open=True)


def register(subparsers: argparse._SubParsersAction, summary: str) -> None:
    parser = subparsers.add_parser(
        "replay",
        help=summary,
        description="Play a joint trajectory CSV through the arms' position servos in MuJoCo without liquid (the "
        "liquid as a rigid payload), report per-joint tracking error and the vessel lips' path errors, and end with "
        "PASS (every lip within the tolerance of its commanded path, no contact) or FAIL. Exit status: 0 pass, "
        "1 fail, 2 bad input.",
    )
    parser.add_argument("trajectory", help="trajectory CSV: time, <arm>/<joint>.pos/.vel/.acc columns")
    parser.add_argument("--json", action="store_true", help="print the results as JSON (with verdict and tolerance_m)")
    parser.add_argument(
        "--tolerance-mm", type=float, default=DEFAULT_TOLERANCE_M * 1000.0,
        help=f"largest lip path error that passes, in {TOLERANCE_MM.allowed()} (default {DEFAULT_TOLERANCE_M * 1000:g})",
    )
    parser.add_argument("--model", default=None, help="scene MJCF written by cosim.robots (default: the project's scene)")
    parser.add_argument(
        "--payload", choices=[m.value for m in PayloadMode], default=PayloadMode.FULL.value,
        help="rigid liquid payload: full (pourer full to the rim, catcher holding that volume) or empty",
    )
    parser.add_argument(
        "--feedforward", choices=[f.value for f in Feedforward], default=Feedforward.DYNAMICS.value,
        help="servo feedforward: plus inverse dynamics of the commanded motion, as an arm's model-based controller "
        "(default), or gravity compensation only (the lip then lags by about the commanded acceleration x inertia / "
        "servo gain)",
    )
    parser.set_defaults(func=run)


def _print_table(report: ReplayReport) -> None:
    print(f"replayed {report.duration:.3f} s in {report.steps} steps of {report.timestep * 1000:.1f} ms")
    print(f"{'joint':<28} {'max error [deg]':>16} {'RMS error [deg]':>16} {'peak torque [%]':>16}")
    for name, mx, rms, tq in zip(report.joint_names, report.joint_max_error, report.joint_rms_error, report.peak_torque_fraction):
        print(f"{name:<28} {math.degrees(mx):>16.4f} {math.degrees(rms):>16.4f} {100 * tq:>16.1f}")
    for vessel in report.lip_max_error:
        print(
            f"{vessel} lip path error: max {report.lip_max_error[vessel] * 1000:.3f} mm, "
            f"RMS {report.lip_rms_error[vessel] * 1000:.3f} mm"
        )
    if report.first_contact is None:
        print("contacts: none")
    else:
        c = report.first_contact
        print(f"contacts: {report.contact_steps} steps; first at t={c.time:.3f} s: {c.geom1} ({c.body1}) - {c.geom2} ({c.body2})")


def run(args: argparse.Namespace) -> int:
    from cosim.robots.scene import RobotScene
    from cosim.trajectory.csv_file import read_trajectory_csv
    from cosim.trajectory.replay import replay

    tolerance = TOLERANCE_MM.check("--tolerance-mm", args.tolerance_mm) / 1000.0
    scene = RobotScene.load(args.model, PayloadMode(args.payload))
    joints = [name for arm in scene.arms.values() for name in arm.joints]
    trajectory = read_trajectory_csv(args.trajectory, known_joints=joints)
    report = replay(scene, trajectory, Feedforward(args.feedforward))
    failures = report.failures(tolerance)
    if args.json:
        verdict = {"verdict": "fail" if failures else "pass", "tolerance_m": tolerance, "failures": failures}
        print(json.dumps({**verdict, **report.to_json()}, indent=2))
    else:
        _print_table(report)
        if failures:
            print(f"FAIL: {'; '.join(failures)}")
        else:
            print(f"PASS: every vessel lip within {tolerance * 1000:.3f} mm of its commanded path, no contact")
    return 1 if failures else 0
