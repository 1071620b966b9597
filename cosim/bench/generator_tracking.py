"""How the joint trajectory generator tracks a smooth path: the source of the exported trajectory's chatter.

    python -m cosim.bench.generator_tracking [--frequency HZ] [--amplitudes RAD ...]

Streams a sinusoidal joint path q0 + A sin(2 pi f t) d (d weights the pour arm's shoulder_lift, elbow and wrist_1
by 0.5, 1, 1) into :class:`cosim.trajectory.generator.TrajectoryGenerator` at the control rate, as the coupling
does, in three ways: the targets alone (derivatives estimated from the last three), the targets with the path's
exact velocity and acceleration, and one period late with central-difference derivatives. For each it prints the
targets the generator reached late, the largest position error against the path, and the share of 2 ms samples
whose jerk sits at the joint's limit. A path within every limit (0.01 rad at 2 Hz needs 1.6 rad/s^2 and 20 rad/s^3
against 5 and 100) that still leaves the jerk at its limit on most samples says the chatter comes from the
generator's state-to-state profiles (jerk at the limit or zero in each phase), not from the path.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.trajectory.generator import GeneratorSettings, TrajectoryGenerator
from cosim.trajectory.limits import scene_limits

CONTROL_PERIOD = 0.01  # s, the coupling's target interval
CYCLE = 0.002  # s, the generator's step (MuJoCo's)
DURATION = 3.0  # s of path per case
SETTLE = 1.0  # s skipped before the statistics (the start from rest)
WEIGHTS = np.array([0.0, 0.5, 1.0, 1.0, 0.0, 0.0])  # per pour-arm joint, base to tip
AT_LIMIT = 0.99  # a sample's jerk counts as at the limit above this fraction of it
MODES = ("estimated", "exact", "one period late")


def track(mode: str, amplitude: float, frequency: float) -> dict[str, float]:
    """Stream the path into a generator for the pour arm; returns late targets, max error (rad) and the share of
    samples with the jerk at its limit."""
    scene = RobotScene.load()
    limits = scene_limits(scene, {})[ArmRole.POUR]
    q0 = scene.joint_positions(ArmRole.POUR)
    w = 2.0 * math.pi * frequency
    jerk_limit = limits.array("max_jerk")

    def path(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, c = math.sin(w * t), math.cos(w * t)
        return q0 + amplitude * s * WEIGHTS, amplitude * w * c * WEIGHTS, -amplitude * w * w * s * WEIGHTS

    generator = TrajectoryGenerator(limits, q0, GeneratorSettings(CYCLE, CONTROL_PERIOD))
    history: list[np.ndarray] = []
    errors, at_limit, previous = [], [], None
    lag = CONTROL_PERIOD if mode == "one period late" else 0.0
    for k in range(int(DURATION / CONTROL_PERIOD)):
        t = k * CONTROL_PERIOD
        q, v, a = path(t)
        history = (history + [q])[-3:]
        if mode == "exact":
            generator.set_target(q, v, a)
        elif mode == "one period late" and len(history) == 3:
            central_v = (history[2] - history[0]) / (2.0 * CONTROL_PERIOD)
            central_a = (history[2] - 2.0 * history[1] + history[0]) / CONTROL_PERIOD**2
            generator.set_target(history[1], central_v, central_a)
        else:
            generator.set_target(q)
        for _ in range(round(CONTROL_PERIOD / CYCLE)):
            position, _, acceleration = generator.step()
            if previous is not None and t >= SETTLE:
                at_limit.append(bool(np.any(np.abs(acceleration - previous) / CYCLE > AT_LIMIT * jerk_limit)))
            previous = acceleration
        if t >= SETTLE:
            errors.append(float(np.max(np.abs(position - path(t + CONTROL_PERIOD - lag)[0]))))
    return {"late_targets": generator.late_targets, "max_error": max(errors), "jerk_at_limit": float(np.mean(at_limit))}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.bench.generator_tracking", description=__doc__.split("\n")[0])
    parser.add_argument("--frequency", type=float, default=2.0, help="path frequency, Hz (default 2: the slosh's)")
    parser.add_argument("--amplitudes", type=float, nargs="+", default=[0.002, 0.01, 0.03], help="rad")
    args = parser.parse_args(argv)
    targets = int(DURATION / CONTROL_PERIOD)
    print(f"{'mode':16s} {'amplitude rad':>13s} {'late targets':>13s} {'max error rad':>14s} {'jerk at limit':>14s}")
    for mode in MODES:
        for amplitude in args.amplitudes:
            r = track(mode, amplitude, args.frequency)
            print(f"{mode:16s} {amplitude:13.4f} {r['late_targets']:>6d} of {targets:<4d} {r['max_error']:14.2e} "
                  f"{100 * r['jerk_at_limit']:13.0f}%")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
