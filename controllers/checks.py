"""Validation helpers for the controllers' frozen configuration dataclasses.

Each check raises :class:`ControllerInputError` with one line in the project's format
(``field: must be in (lo, hi] unit, got value``), so the CLI prints controller and scene errors alike.
"""

from __future__ import annotations

import math
from enum import Enum
from typing import TypeVar

from controllers.errors import ControllerInputError

E = TypeVar("E", bound=Enum)


def check_range(
    field: str,
    value: object,
    lo: float | None = None,
    hi: float | None = None,
    unit: str = "",
    lo_open: bool = False,
    hi_open: bool = False,
) -> float:
    """Return ``value`` as a float if it is a finite number with ``lo <= value <= hi`` (bounds optional/open)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ControllerInputError(f"{field}: must be a number, got {value!r} ({type(value).__name__})")
    v = float(value)
    below = lo is not None and (v <= lo if lo_open else v < lo)
    above = hi is not None and (v >= hi if hi_open else v > hi)
    if not math.isfinite(v) or below or above:
        left = "-inf" if lo is None else f"{lo:g}"
        right = "inf" if hi is None else f"{hi:g}"
        interval = f"{'(' if lo_open or lo is None else '['}{left}, {right}{')' if hi_open or hi is None else ']'}"
        suffix = f" {unit}" if unit else ""
        raise ControllerInputError(f"{field}: must be in {interval}{suffix}, got {v:g}")
    return v


def check_choice(field: str, value: object, enum_type: type[E]) -> E:
    """Coerce ``value`` (an enum member or its value) into ``enum_type``."""
    if isinstance(value, enum_type):
        return value
    for member in enum_type:
        if value == member.value:
            return member
    allowed = ", ".join(repr(m.value) for m in enum_type)
    raise ControllerInputError(f"{field}: must be one of {allowed}, got {value!r}")
