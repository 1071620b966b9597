"""Joint trajectory JSON: write and read; per arm it mirrors ROS ``trajectory_msgs/JointTrajectory``.

Layout (one object; numbers in SI units, listed in ``units``)::

    {"format": "cosim.joint_trajectory.v2",
     "units": {"time": "s", "position": "rad", "velocity": "rad/s", "acceleration": "rad/s^2", "jerk": "rad/s^3"},
     "sample_rate_hz": 500.0,
     "arms": {"pour_arm": {"arm_model": "UR10e",
                           "joint_names": ["pour_arm_shoulder_pan_joint", ...],
                           "scene_joint_names": ["pour_arm/shoulder_pan", ...],
                           "limits": {"max_velocity": [...], "max_acceleration": [...], "max_jerk": [...],
                                      "min_position": [...], "max_position": [...]},
                           "points": [{"positions": [...], "velocities": [...], "accelerations": [...],
                                       "time_from_start": {"sec": 0, "nanosec": 2000000}}, ...]},
              "catch_arm": {...}}}

Per arm this is a ROS ``trajectory_msgs/JointTrajectory`` (``joint_names``, ``points`` of
``JointTrajectoryPoint``, :mod:`cosim.trajectory.ros_points`) plus the arm model, the scene's names of the same
joints (the CSV's column stems) and the limits the trajectory was generated under, per joint in ``joint_names``
order. ``joint_names`` are the names the arm's ROS 2 driver uses, with the scene's prefix
(:mod:`cosim.trajectory.driver_names`). Every arm has the same points' times. Numbers are written with Python's
shortest round-trip repr: positions, velocities and accelerations read back exactly, equal to the CSV of the same run
(:mod:`cosim.trajectory.csv_file`).

Writing is atomic (:mod:`cosim.atomic_files`). Reading validates everything and raises :class:`InputError` with one
line naming the file, the field (e.g. ``arms.pour_arm.points[3].positions``) and the problem.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cosim.atomic_files import atomic_path
from cosim.errors import InputError
from cosim.trajectory.joint_trajectory import JointTrajectory
from cosim.trajectory.limits import LIMIT_FIELDS, ArmLimits, JointLimits
from cosim.trajectory.ros_points import NANOSECONDS, POINT_FIELDS, arm_columns, check_driver_names, points

FORMAT = "cosim.joint_trajectory.v2"
UNITS = {"time": "s", "position": "rad", "velocity": "rad/s", "acceleration": "rad/s^2", "jerk": "rad/s^3"}


@dataclass(frozen=True)
class TrajectoryDocument:
    """A trajectory file's content: the samples of all arms (columns in file order, the scene's joint names), the
    sample rate (Hz), each arm's limits (with its arm model) and each arm's joints as its ROS 2 driver names them
    (arm name -> names, in the limits' joint order)."""

    trajectory: JointTrajectory
    sample_rate_hz: float
    limits: tuple[ArmLimits, ...]
    driver_joint_names: dict[str, tuple[str, ...]]


def trajectory_json_text(
    trajectory: JointTrajectory, limits: Sequence[ArmLimits], sample_rate_hz: float, driver_names: Mapping[str, Sequence[str]]
) -> str:
    """The JSON text of ``trajectory`` with the ``limits`` of its arms (their joints, in order, must be its columns)
    and their joints' ``driver_names`` (arm name -> names, in the limits' order)."""
    names = tuple(n for arm in limits for n in arm.joint_names)
    if names != trajectory.joint_names:
        raise ValueError(f"trajectory JSON: the limits' joints {names} are not the trajectory's {trajectory.joint_names}")
    check_driver_names(limits, driver_names)
    arms = {
        arm.arm: {
            "arm_model": arm.arm_model,
            "joint_names": list(driver_names[arm.arm]),
            "scene_joint_names": list(arm.joint_names),
            "limits": {field: [float(v) for v in arm.array(field)] for field in LIMIT_FIELDS},
            "points": points(trajectory, cols),
        }
        for arm, cols in arm_columns(limits)
    }
    document = {"format": FORMAT, "units": UNITS, "sample_rate_hz": float(sample_rate_hz), "arms": arms}
    return json.dumps(document, separators=(",", ":"), allow_nan=False) + "\n"


def write_json_text(path: str | Path, text: str) -> None:
    """Write ``text`` (from :func:`trajectory_json_text`) to ``path`` atomically, readable by all like the CSV."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
        tmp.chmod(0o644)


def _numbers(source: str, field: str, value: object, n: int) -> list[float]:
    ok = isinstance(value, list) and len(value) == n and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value
    )
    if not ok:
        raise InputError(f"{source}: {field}: must be a list of {n} finite numbers")
    return [float(v) for v in value]  # type: ignore[union-attr]


def _object(source: str, field: str, value: object, keys: Sequence[str]) -> dict:
    if not isinstance(value, dict):
        raise InputError(f"{source}: {field}: must be an object")
    missing = [k for k in keys if k not in value]
    if missing:
        raise InputError(f"{source}: {field}: missing key(s) {', '.join(missing)}")
    return value


def _time(source: str, field: str, value: object) -> float:
    stamp = _object(source, field, value, ("sec", "nanosec"))
    sec, nanosec = stamp["sec"], stamp["nanosec"]
    if not all(isinstance(v, int) and not isinstance(v, bool) for v in (sec, nanosec)) or sec < 0 or not 0 <= nanosec < NANOSECONDS:
        raise InputError(f"{source}: {field}: sec must be an integer >= 0 and nanosec an integer in [0, {NANOSECONDS})")
    return sec + nanosec / NANOSECONDS


def _names(source: str, field: str, value: object, n: int | None = None) -> tuple[str, ...]:
    """A list of unique non-empty names (``n`` of them, where given)."""
    count = "" if n is None else f" {n}"
    ok = isinstance(value, list) and value and all(isinstance(j, str) and j for j in value) and len(set(value)) == len(value)
    if not ok or (n is not None and len(value) != n):  # type: ignore[arg-type]
        raise InputError(f"{source}: {field}: must be a non-empty list of{count} unique names")
    return tuple(value)  # type: ignore[arg-type]


def _read_arm(source: str, name: str, value: object) -> tuple[ArmLimits, tuple[str, ...], list[float], np.ndarray]:
    """(limits, driver joint names, times (N,), samples (3, N, n)) of one arm."""
    p = f"arms.{name}"
    arm = _object(source, p, value, ("arm_model", "joint_names", "scene_joint_names", "limits", "points"))
    joints = _names(source, f"{p}.scene_joint_names", arm["scene_joint_names"])
    n = len(joints)
    driver = _names(source, f"{p}.joint_names", arm["joint_names"], n)
    raw = _object(source, f"{p}.limits", arm["limits"], LIMIT_FIELDS)
    values = {f: _numbers(source, f"{p}.limits.{f}", raw[f], n) for f in LIMIT_FIELDS}
    try:
        limits = ArmLimits(
            arm=name,
            arm_model=arm["arm_model"],
            joints=tuple(JointLimits(name=j, **{f: values[f][i] for f in LIMIT_FIELDS}) for i, j in enumerate(joints)),
        )
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
    points = arm["points"]
    if not isinstance(points, list):
        raise InputError(f"{source}: {p}.points: must be a list")
    times, samples = [], np.empty((len(POINT_FIELDS), len(points), n))
    for i, point in enumerate(points):
        q = f"{p}.points[{i}]"
        point = _object(source, q, point, (*POINT_FIELDS, "time_from_start"))
        for k, f in enumerate(POINT_FIELDS):
            samples[k, i] = _numbers(source, f"{q}.{f}", point[f], n)
        times.append(_time(source, f"{q}.time_from_start", point["time_from_start"]))
    return limits, driver, times, samples


def read_trajectory_json(path: str | Path) -> TrajectoryDocument:
    """Read and validate a trajectory JSON (``InputError`` with one line on any problem)."""
    path = Path(path)
    source = str(path)
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{source}: file not found") from None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise InputError(f"{source}: not a readable JSON file ({str(exc).splitlines()[0]})") from None
    document = _object(source, "document", document, ("format", "units", "sample_rate_hz", "arms"))
    if document["format"] != FORMAT:
        raise InputError(f"{source}: format: must be {FORMAT!r}, got {document['format']!r}")
    if document["units"] != UNITS:
        raise InputError(f"{source}: units: must be {UNITS}, got {document['units']!r}")
    rate = document["sample_rate_hz"]
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not math.isfinite(rate) or rate <= 0:
        raise InputError(f"{source}: sample_rate_hz: must be a positive number, got {rate!r}")
    arms = document["arms"]
    if not isinstance(arms, dict) or not arms:
        raise InputError(f"{source}: arms: must be a non-empty object")
    limits, driver, blocks, times = [], {}, [], None
    for name, value in arms.items():
        arm_limits, driver[name], arm_times, samples = _read_arm(source, name, value)
        if times is not None and arm_times != times:
            raise InputError(f"{source}: arms.{name}.points: the times differ from the first arm's")
        times = arm_times
        limits.append(arm_limits)
        blocks.append(samples)
    block = np.concatenate(blocks, axis=2)
    try:
        trajectory = JointTrajectory(
            np.array(times), tuple(n for arm in limits for n in arm.joint_names), block[0], block[1], block[2]
        )
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
    return TrajectoryDocument(trajectory, float(rate), tuple(limits), driver)
