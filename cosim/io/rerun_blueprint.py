"""The default Rerun blueprint of a pour: the 3-D view framed on the pour, in a column of the window's full height;
beside it one plot panel per scalar signal, in a tab per signal group, over the controller's log and the liquid's
colour scale.

A signal's name is ``<group>/<quantity>_<unit>`` (``pour_arm/joint_angle_deg``, ``pourer/liquid_force_N``); its
panel is titled ``<group> <quantity> (<unit>)`` ("pour_arm joint angle (deg)") and sits in the tab ``<group>``.
Units the title spells out are the keys of :data:`UNITS`; a name without one gets a title without a unit. A
signal with several series (one entity, ``SeriesLines`` names) shows its legend in the top-left corner; a
single-series panel needs none, its title says what it plots.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import rerun.blueprint as rrb
from matplotlib import colormaps

from cosim.io import rerun_paths

# Name suffix -> unit as shown, longest suffixes first (``_deg_s`` before ``_deg``, ``_N_m`` before ``_N``).
UNITS = {"_deg_s": "deg/s", "_mm_s": "mm/s", "_m_s": "m/s", "_N_m": "N m", "_deg": "deg", "_mL": "mL", "_mm": "mm", "_N": "N"}
# Share of the window width given to the 3-D view and to the column of plots, log and colour scale: the 3-D view,
# the window's full height, comes out a little narrower than high (0.85 in a 16:10 window, 0.9 in a 16:9 one), as
# the pour is, its vessels and stream seen from the side (:data:`cosim.io.rerun_framing.VIEW_ASPECT`).
_COLUMN_SHARES = [5.0, 7.0]
# Share of the right column's height given to the plot tabs and to the log + colour scale row.
_RIGHT_ROW_SHARES = [3.0, 1.0]
# Plot panels per row of a tab's grid.
_GRID_COLUMNS = 1


@dataclass(frozen=True)
class Camera:
    """The 3-D view's starting camera: ``eye`` and ``target`` (3,) m, world frame, z up."""

    eye: tuple[float, float, float]
    target: tuple[float, float, float]


def split_unit(name: str) -> tuple[str, str]:
    """(quantity, unit) of a signal name's last part: ``joint_speed_deg_s`` -> (``joint_speed``, ``deg/s``);
    unit '' when the name ends in none of :data:`UNITS`."""
    last = rerun_paths.name_parts(name)[-1]
    for suffix, unit in UNITS.items():
        if last.endswith(suffix) and len(last) > len(suffix):
            return last[: -len(suffix)], unit
    return last, ""


def panel_title(name: str) -> str:
    """Title of a signal's panel: ``pour_arm joint angle (deg)``."""
    parts = rerun_paths.name_parts(name)
    quantity, unit = split_unit(name)
    words = " ".join([*parts[:-1], quantity.replace("_", " ")])
    return f"{words} ({unit})" if unit else words


def colour_scale_text(colormap: str, top: float, note: str = "") -> str:
    """Markdown stating the liquid's colour scale: ``colormap`` from 0 to ``top`` m/s, the colours named by hex
    code at 0, top/2 and top; ``note`` appended."""
    cmap = colormaps[colormap]
    stops = [(0.0, "0"), (0.5, f"{top / 2:g}"), (1.0, f"{top:g}")]
    colours = ", ".join(f"`#{''.join(f'{c:02x}' for c in np.asarray(cmap(f, bytes=True))[:3])}` = {v} m/s" for f, v in stops)
    text = f"**Liquid colour: speed**, {colormap} colour map from 0 to {top:g} m/s (faster is {top:g} m/s's colour): {colours}."
    return f"{text}\n\n{note}" if note else text


def _plot(name: str, series: int) -> rrb.TimeSeriesView:
    legend = rrb.PlotLegend(corner=rrb.components.Corner2D.LeftTop, visible=series > 1)
    return rrb.TimeSeriesView(origin=rerun_paths.signal_path(name), name=panel_title(name), plot_legend=legend)


def build_blueprint(signal_names: Iterable[str], camera: Camera | None = None, series: dict[str, int] | None = None) -> rrb.Blueprint:
    """The default blueprint for a recording whose scalar signals are ``signal_names`` (in first-logged order).

    camera: the 3-D view's starting eye and target (None: Rerun frames the whole scene). series: signal name ->
    number of series (a legend is shown where there are several; default 1)."""
    series = series or {}
    tabs: dict[str, list[rrb.TimeSeriesView]] = {}
    for name in signal_names:
        tabs.setdefault(rerun_paths.name_parts(name)[0], []).append(_plot(name, series.get(name, 1)))
    eye = None if camera is None else rrb.EyeControls3D(
        kind=rrb.components.Eye3DKind.Orbital, position=camera.eye, look_target=camera.target, eye_up=(0.0, 0.0, 1.0)
    )
    space = rrb.Spatial3DView(
        origin=rerun_paths.WORLD, name="pour, world frame (m); liquid coloured by speed", eye_controls=eye,
        line_grid=rrb.LineGrid3D(visible=True, spacing=0.1),
    )
    notes = rrb.Horizontal(
        rrb.TextLogView(origin=rerun_paths.EVENTS, name="controller log"),
        rrb.TextDocumentView(origin=rerun_paths.LEGEND, name="colour scale"),
        column_shares=[2.0, 1.0],
    )
    grids = [rrb.Grid(*plots, grid_columns=_GRID_COLUMNS, name=group) for group, plots in tabs.items()]
    right = rrb.Vertical(rrb.Tabs(*grids), notes, row_shares=_RIGHT_ROW_SHARES) if grids else notes
    layout = rrb.Horizontal(space, right, column_shares=_COLUMN_SHARES)
    return rrb.Blueprint(
        layout, rrb.TimePanel(timeline=rerun_paths.TIMELINE_TIME), rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
    )
