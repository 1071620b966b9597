"""Which configurations of the stress matrix a ``cosim stress --filter FIELD=VALUE`` selects (a module of its own,
without the matrix's imports, so that ``cosim stress --help`` can list the fields)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from cosim.errors import InputError

if TYPE_CHECKING:
    from cosim.stress.matrix import StressConfig

FILTER_FIELDS = ("motion", "level", "fill", "across", "cfl", "dim", "solver", "id")


def _matches(config: StressConfig, name: str, value: str) -> bool:
    if name == "id":
        return config.id == value
    actual = dict(item.split("=", 1) for item in config.key.split(";"))[name]
    try:
        return math.isclose(float(actual), float(value))
    except ValueError:
        return actual == value


def select(configs: list[StressConfig], filters: list[str]) -> list[StressConfig]:
    """Configurations that match every ``FIELD=VALUE`` filter (e.g. ``motion=tilt``, ``dim=3``, ``level=5``)."""
    out = configs
    for f in filters:
        name, sep, value = f.partition("=")
        if not sep or name not in FILTER_FIELDS:
            raise InputError(f"--filter {f!r}: expected FIELD=VALUE with FIELD one of {', '.join(FILTER_FIELDS)}")
        out = [c for c in out if _matches(c, name, value)]
    return out
