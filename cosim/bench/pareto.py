"""Pareto front of (cost, error) points: the configurations no other one beats on both."""

from __future__ import annotations

import math
from collections.abc import Sequence


def pareto_front(points: Sequence[tuple[float, float]]) -> list[int]:
    """Indices of the non-dominated points, by increasing cost. Both coordinates are minimised; a point is dominated
    when another is no worse in both and better in one. Points with a NaN coordinate are left out; of exact
    duplicates the first is kept."""
    valid = [i for i, (c, e) in enumerate(points) if not (math.isnan(c) or math.isnan(e))]
    order = sorted(valid, key=lambda i: (points[i][0], points[i][1], i))
    front: list[int] = []
    best_error = math.inf
    for i in order:
        if points[i][1] < best_error:
            front.append(i)
            best_error = points[i][1]
    return front
