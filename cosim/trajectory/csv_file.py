"""Joint trajectory CSV: write and read a :class:`~cosim.trajectory.joint_trajectory.JointTrajectory`.

Format: a header row, then one row per time sample. Column ``time`` (s, strictly increasing) first, then for each
joint, in order, ``<arm>/<joint>.pos`` (rad), ``<arm>/<joint>.vel`` (rad/s), ``<arm>/<joint>.acc`` (rad/s^2), e.g.
``pour_arm/shoulder_pan.pos``. Numbers are written with Python's shortest round-trip repr, so a write/read round
trip is exact.

Reading validates everything and raises :class:`cosim.errors.InputError` with one line naming the file, the line
(the header is line 1) or column, and the problem: missing or duplicate columns, a joint without all three
quantities, an unknown joint, a non-numeric or non-finite value, a short row, non-increasing time. Writing is atomic
(temporary file in the target directory, then ``os.replace``): a failed write leaves no partial file.
"""

from __future__ import annotations

import csv
import math
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from cosim.errors import InputError
from cosim.trajectory.joint_trajectory import MIN_SAMPLES, JointTrajectory

TIME_COLUMN = "time"
QUANTITIES = ("pos", "vel", "acc")  # column suffixes, in file order per joint


def header(joint_names: Iterable[str]) -> list[str]:
    """The CSV header for ``joint_names``."""
    return [TIME_COLUMN] + [f"{name}.{q}" for name in joint_names for q in QUANTITIES]


def write_trajectory_csv(path: str | Path, trajectory: JointTrajectory) -> None:
    """Write ``trajectory`` to ``path`` atomically (parent directories are created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    block = np.stack((trajectory.positions, trajectory.velocities, trajectory.accelerations), axis=2)
    block = block.reshape(trajectory.time.size, -1)  # per joint: pos, vel, acc
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(header(trajectory.joint_names))
            for t, row in zip(trajectory.time, block):
                writer.writerow([repr(float(t))] + [repr(float(v)) for v in row])
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _parse_header(path: Path, row: list[str], known: set[str] | None) -> list[str]:
    if not row or row[0].strip() != TIME_COLUMN:
        first = row[0] if row else ""
        raise InputError(f"{path}: line 1: the first column must be {TIME_COLUMN!r}, got {first!r}")
    seen: dict[str, set[str]] = {}
    order: list[str] = []
    for column in (c.strip() for c in row[1:]):
        name, dot, quantity = column.rpartition(".")
        if not dot or not name or quantity not in QUANTITIES:
            raise InputError(f"{path}: line 1: column {column!r} is not <arm>/<joint>.pos|.vel|.acc")
        if known is not None and name not in known:
            raise InputError(f"{path}: line 1: column {column!r} names an unknown joint {name!r}")
        if name not in seen:
            seen[name] = set()
            order.append(name)
        if quantity in seen[name]:
            raise InputError(f"{path}: line 1: duplicate column {column!r}")
        seen[name].add(quantity)
    if not order:
        raise InputError(f"{path}: line 1: no joint columns")
    for name in order:
        missing = [q for q in QUANTITIES if q not in seen[name]]
        if missing:
            raise InputError(f"{path}: line 1: joint {name!r} lacks column(s) {', '.join(f'{name}.{q}' for q in missing)}")
    expected = header(order)
    if [c.strip() for c in row] != expected:
        raise InputError(f"{path}: line 1: columns must be grouped per joint as .pos, .vel, .acc")
    return order


def read_trajectory_csv(path: str | Path, known_joints: Iterable[str] | None = None) -> JointTrajectory:
    """Read a trajectory CSV; ``known_joints`` (full names), when given, is the set of joints allowed in the file."""
    path = Path(path)
    known = set(known_joints) if known_joints is not None else None
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            rows = list(csv.reader(handle))
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{path}: unreadable ({exc})") from None
    if not rows:
        raise InputError(f"{path}: empty file")
    names = _parse_header(path, rows[0], known)
    columns = header(names)
    values = []
    for line, row in enumerate(rows[1:], start=2):
        if not row or all(not c.strip() for c in row):
            continue
        if len(row) != len(columns):
            raise InputError(f"{path}: line {line}: {len(row)} values, the header has {len(columns)} columns")
        parsed = []
        for column, text in zip(columns, row):
            try:
                value = float(text)
            except ValueError:
                raise InputError(f"{path}: line {line}, column {column!r}: {text.strip()!r} is not a number") from None
            if not math.isfinite(value):
                raise InputError(f"{path}: line {line}, column {column!r}: {text.strip()!r} is not finite")
            parsed.append(value)
        if values and parsed[0] <= values[-1][0]:
            raise InputError(
                f"{path}: line {line}, column {TIME_COLUMN!r}: time {parsed[0]!r} s does not increase "
                f"(previous {values[-1][0]!r} s)"
            )
        values.append(parsed)
    if len(values) < MIN_SAMPLES:
        raise InputError(f"{path}: {len(values)} data row(s), a trajectory needs at least {MIN_SAMPLES}")
    data = np.array(values)
    block = data[:, 1:].reshape(len(values), len(names), len(QUANTITIES))
    return JointTrajectory(data[:, 0], tuple(names), block[:, :, 0], block[:, :, 1], block[:, :, 2])
