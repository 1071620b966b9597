"""The checks of configuration values.

Every check raises :class:`declared_settings.errors.InputError` with one line that names the field, the allowed
range and the value that was given, e.g. ``fluid.spacing: must be in (0, 0.05] m, got -0.01``.
"""

from __future__ import annotations

import math
from enum import Enum
from typing import TypeVar

from declared_settings.errors import InputError

E = TypeVar("E", bound=Enum)


def value_text(value: object) -> str:
    """A given value as a message shows it: a string quoted, anything else as printed."""
    return repr(value) if isinstance(value, str) else f"{value}"


def check_number(field: str, value: object) -> float:
    """Return ``value`` as a float; reject bools, non-numbers and NaN/inf."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{field}: must be a number, got {value_text(value)} ({type(value).__name__})")
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
    x = value if isinstance(value, int) else v  # an integer compared exactly: 2**63 - 1 has no float
    below = lo is not None and (x <= lo if lo_open else x < lo)
    above = hi is not None and (x >= hi if hi_open else x > hi)
    if below or above:
        suffix = f" {unit}" if unit else ""
        raise InputError(f"{field}: must be in {interval_text(lo, hi, lo_open, hi_open)}{suffix}, got {v:g}")
    return v


def interval_text(lo: float | str | None, hi: float | str | None, lo_open: bool = False, hi_open: bool = False) -> str:
    """The interval as messages and references write it, e.g. ``(0, 0.05]``; a None bound is infinite, a name (of
    another setting) is written as it is, e.g. ``(0, max_accel]``."""
    left = "-inf" if lo is None else lo if isinstance(lo, str) else f"{lo:g}"
    right = "inf" if hi is None else hi if isinstance(hi, str) else f"{hi:g}"
    return f"{'(' if lo_open or lo is None else '['}{left}, {right}{')' if hi_open or hi is None else ']'}"


def check_int(field: str, value: object, lo: int | None = None, hi: int | None = None) -> int:
    """Check an integer in ``[lo, hi]``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"{field}: must be an integer, got {value_text(value)} ({type(value).__name__})")
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
    raise InputError(f"{field}: must be one of {allowed}, got {value_text(value)}")


def check_vector(field: str, value: object, length: int) -> tuple[float, ...]:
    """Check a finite numeric sequence of the given length; return it as a tuple of floats."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != length:  # type: ignore[arg-type]
        raise InputError(f"{field}: must be a list of {length} numbers, got {value_text(value)}")
    return tuple(check_number(f"{field}[{i}]", x) for i, x in enumerate(value))  # type: ignore[union-attr]
