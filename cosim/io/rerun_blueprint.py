"""The default Rerun blueprint of a pour: a 3-D view of ``world``, the phase log, one time-series panel per group.

Signals are grouped into panels by the first part of their name, split further by the suffix after the last ``.``
of the last part (so ``joints/pour_arm/elbow.pos`` and ``joints/pour_arm/elbow.vel`` land in separate panels,
"joints .pos" and "joints .vel", matching the trajectory CSV's ``<arm>/<joint>.pos|.vel|.acc`` columns). Examples:
``pourer/theta`` and ``pourer/theta1`` share the panel "pourer"; ``volume/in_pourer`` and ``volume/spilled`` share
"volume". Within a panel a series is labelled by the rest of its name (``pour_arm/elbow.pos``).
"""

from __future__ import annotations

from collections.abc import Iterable

import rerun.blueprint as rrb

from cosim.io import rerun_paths

# Share of the window width given to the 3-D view + phase log column, and to the plot grid.
_COLUMN_SHARES = [1.0, 1.0]
# Share of the left column's height given to the 3-D view and to the phase log.
_LEFT_ROW_SHARES = [4.0, 1.0]
# Plot panels per row of the grid.
_GRID_COLUMNS = 2


def panel_key(name: str) -> tuple[str, str]:
    """(group, suffix) of a signal: its first name part and the ``.suffix`` of its last part ('' if none)."""
    parts = rerun_paths.signal_parts(name)
    last = parts[-1]
    suffix = last[last.rindex(".") :] if len(parts) > 1 and "." in last else ""
    return parts[0], suffix


def panel_title(key: tuple[str, str]) -> str:
    """Readable title of a panel, e.g. ``joints .pos`` or ``volume``."""
    group, suffix = key
    return f"{group} {suffix}" if suffix else group


def series_label(name: str) -> str:
    """Legend label of a signal within its panel: the name without its group (the whole name if one part)."""
    parts = rerun_paths.signal_parts(name)
    return "/".join(parts[1:]) if len(parts) > 1 else parts[0]


def build_blueprint(signal_names: Iterable[str]) -> rrb.Blueprint:
    """The default blueprint for a recording whose scalar signals are ``signal_names`` (in first-logged order)."""
    panels: dict[tuple[str, str], list[str]] = {}
    for name in signal_names:
        panels.setdefault(panel_key(name), []).append(name)
    plots = [
        rrb.TimeSeriesView(
            origin=rerun_paths.signal_path(key[0]),
            contents=[f"+ {rerun_paths.absolute(rerun_paths.signal_path(n))}" for n in names],
            name=panel_title(key),
        )
        for key, names in panels.items()
    ]
    left = rrb.Vertical(
        rrb.Spatial3DView(origin=rerun_paths.WORLD, name="pour (world frame, m)"),
        rrb.TextLogView(origin=rerun_paths.EVENTS, name="controller phase"),
        row_shares=_LEFT_ROW_SHARES,
    )
    layout = rrb.Horizontal(left, rrb.Grid(*plots, grid_columns=_GRID_COLUMNS), column_shares=_COLUMN_SHARES) if plots else left
    return rrb.Blueprint(layout, rrb.TimePanel(timeline=rerun_paths.TIMELINE_TIME))
