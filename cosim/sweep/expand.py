"""A sweep's axes turned into pours: each point of the grid or sample, its values set on the base scene.

A point whose scene is refused (a value out of its key's range) becomes a pour without a scene, carrying the
refusal's one line: it is recorded as failed and the sweep goes on with the others.
"""

from __future__ import annotations

import copy
import itertools
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from cosim.errors import InputError
from cosim.sweep.spec import SweepSpec

if TYPE_CHECKING:
    from cosim.pour_scene import PourScene


@dataclass(frozen=True)
class SweepPoint:
    """One pour of a sweep.

    index: its place in the sweep (0-based, the order of the grid or the draws).
    axes: swept key -> its value at this point.
    scene: the pour's scene, or None where the scene refused a value.
    error: that refusal's line (None with a scene).
    """

    index: int
    axes: dict[str, Any]
    scene: PourScene | None
    error: str | None = None


def axis_points(spec: SweepSpec) -> list[dict[str, Any]]:
    """The axes' values at each point: every combination in mode 'grid' (the last axis varying fastest), ``samples``
    independent draws in mode 'sample' (a list or range axis: one of its values, uniformly; a uniform axis: a value
    in its interval), from one generator seeded with the sweep's seed."""
    keys = [a.key for a in spec.axes]
    if spec.mode == "grid":
        return [dict(zip(keys, combo)) for combo in itertools.product(*(a.values for a in spec.axes))]
    import numpy as np

    rng = np.random.default_rng(spec.seed)
    points = []
    for _ in range(spec.samples):
        point = {}
        for axis in spec.axes:
            if axis.values is None:
                point[axis.key] = float(rng.uniform(*axis.interval))
            else:
                point[axis.key] = axis.values[int(rng.integers(len(axis.values)))]
        points.append(point)
    return points


def with_values(table: dict, values: dict[str, Any]) -> dict:
    """A copy of the scene ``table`` with each dotted key of ``values`` set (sub-tables made where missing);
    InputError where the table holds a value where the key needs a sub-table."""
    out = copy.deepcopy(table)
    for key, value in values.items():
        *sections, leaf = key.split(".")
        node = out
        for depth, section in enumerate(sections):
            node = node.setdefault(section, {})
            if not isinstance(node, dict):
                raise InputError(f"scene.{'.'.join(sections[:depth + 1])}: must be a table, got {node!r}")
        node[leaf] = value
    return out


def expand(spec: SweepSpec) -> list[SweepPoint]:
    """Every pour of ``spec``, in order."""
    from cosim.config_mapping import from_mapping
    from cosim.pour_scene import PourScene

    pours = []
    for index, values in enumerate(axis_points(spec)):
        try:
            scene = from_mapping(PourScene, with_values(spec.base, values), "scene")
        except InputError as exc:
            pours.append(SweepPoint(index, values, None, str(exc)))
            continue
        if spec.base_path is not None:
            scene = scene.named_after(spec.base_path)  # as `cosim pour BASE.toml` names it
        pours.append(SweepPoint(index, values, scene))
    return pours
