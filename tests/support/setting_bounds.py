"""Values at and just beyond a declared setting's bounds, for the tests that check each range from its declaration."""

from __future__ import annotations

import math

from declared_settings.setting import Setting


def _step(spec: Setting, x: float, direction: int) -> float:
    return x + direction if spec.kind == "int" else math.nextafter(x, direction * math.inf)


def outside(spec: Setting, owner: object = None) -> list[float]:
    """The values just outside each finite bound of ``spec`` (the bound itself where it is open); a bound that names
    another setting is read from ``owner``."""
    b = spec.bounds.of(owner)
    values = []
    if b.lo is not None:
        values.append(b.lo if b.lo_open else _step(spec, b.lo, -1))
    if b.hi is not None:
        values.append(b.hi if b.hi_open else _step(spec, b.hi, 1))
    return values


def inside(spec: Setting, owner: object = None) -> list[float]:
    """The values at (or, where open, just inside) each finite bound of ``spec``; named bounds read from ``owner``."""
    b = spec.bounds.of(owner)
    values = []
    if b.lo is not None:
        values.append(_step(spec, b.lo, 1) if b.lo_open else b.lo)
    if b.hi is not None:
        values.append(_step(spec, b.hi, -1) if b.hi_open else b.hi)
    return values
