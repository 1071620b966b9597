"""Validation helpers for frozen configuration dataclasses.

Every check raises :class:`cosim.errors.InputError` with one line that names the field, the allowed range and
the value that was given, e.g. ``fluid.spacing: must be in (0, 0.05] m, got -0.01``.
"""

from __future__ import annotations

import math
import re
from enum import Enum
from typing import TypeVar

from cosim.errors import InputError

E = TypeVar("E", bound=Enum)

# A ROS 2 name token (e.g. a tf prefix): a letter, then letters, digits and underscores; at most this long.
ROS_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
ROS_NAME_MAX = 64


def _fmt(value: object) -> str:
    return repr(value) if isinstance(value, str) else f"{value}"


def check_number(field: str, value: object) -> float:
    """Return ``value`` as a float; reject bools, non-numbers and NaN/inf."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{field}: must be a number, got {_fmt(value)} ({type(value).__name__})")
    if not math.isfinite(value):
        raise InputError(f"{field}: must be a finite number, got {value}")
    return float(value)


def check_range(
    field: str,
    value: object,
    lo: float | None = None,
    hi: float | None = None,
    unit: str = "",
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """Check ``lo <= value <= hi`` (bounds optional, open with ``lo_open``/``hi_open``); return it as float."""
    v = check_number(field, value)
    below = lo is not None and (v <= lo if lo_open else v < lo)
    above = hi is not None and (v >= hi if hi_open else v > hi)
    if below or above:
        suffix = f" {unit}" if unit else ""
        raise InputError(f"{field}: must be in {interval_text(lo, hi, lo_open, hi_open)}{suffix}, got {v:g}")
    return v


def interval_text(lo: float | None, hi: float | None, lo_open: bool = False, hi_open: bool = False) -> str:
    """The interval as messages and references write it, e.g. ``(0, 0.05]``; a None bound is infinite."""
    left = "-inf" if lo is None else f"{lo:g}"
    right = "inf" if hi is None else f"{hi:g}"
    return f"{'(' if lo_open or lo is None else '['}{left}, {right}{')' if hi_open or hi is None else ']'}"


def check_positive(field: str, value: object, unit: str = "", hi: float | None = None) -> float:
    """Check ``0 < value (<= hi)``."""
    return check_range(field, value, 0.0, hi, unit, lo_open=True)


def check_int(field: str, value: object, lo: int | None = None, hi: int | None = None) -> int:
    """Check an integer in ``[lo, hi]``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"{field}: must be an integer, got {_fmt(value)} ({type(value).__name__})")
    check_range(field, value, lo, hi)
    return value


def check_choice(field: str, value: object, enum_type: type[E]) -> E:
    """Coerce ``value`` (an enum member or its value) into ``enum_type``."""
    if isinstance(value, enum_type):
        return value
    for member in enum_type:
        if value == member.value:
            return member
    allowed = ", ".join(repr(m.value) for m in enum_type)
    raise InputError(f"{field}: must be one of {allowed}, got {_fmt(value)}")


def check_vector(field: str, value: object, length: int) -> tuple[float, ...]:
    """Check a finite numeric sequence of the given length; return it as a tuple of floats."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != length:  # type: ignore[arg-type]
        raise InputError(f"{field}: must be a list of {length} numbers, got {_fmt(value)}")
    return tuple(check_number(f"{field}[{i}]", x) for i, x in enumerate(value))  # type: ignore[union-attr]


def check_device(field: str, value: object) -> str:
    """A warp device name: 'cpu', 'cuda' or 'cuda:N' (availability is checked when the device is opened)."""
    if isinstance(value, str) and (value in ("cpu", "cuda") or (value.startswith("cuda:") and value[5:].isdigit())):
        return value
    raise InputError(f"{field}: must be 'cpu', 'cuda' or 'cuda:N', got {_fmt(value)}")


def check_ros_name(field: str, value: object, allow_empty: bool = False) -> str:
    """A ROS 2 name token (e.g. a tf prefix): a letter, then letters, digits or '_', at most :data:`ROS_NAME_MAX`
    characters; ``''`` too where ``allow_empty``."""
    if isinstance(value, str) and ((value == "" and allow_empty) or (ROS_NAME.fullmatch(value) and len(value) <= ROS_NAME_MAX)):
        return value
    empty = " or ''" if allow_empty else ""
    raise InputError(
        f"{field}: must be a letter followed by letters, digits or '_' (at most {ROS_NAME_MAX} characters){empty}, "
        f"got {_fmt(value)}"
    )
