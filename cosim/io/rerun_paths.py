"""Entity paths and timelines of a cosim Rerun recording: the one place that names them.

Layout of a recording (all 3-D data in the MuJoCo world frame: metres, z up):

- ``world``                                 view coordinates (right-handed, z up), static
- ``world/robot/<body>``                    Transform3D body -> world, on the timelines (bodies that carry a
                                              drawn geom; not the world body, whose frame is the world frame)
- ``world/robot/<body>/<geom>``             static Transform3D geom -> body plus the geom's shape
- ``world/liquid``                          Points3D of the (decimated) liquid particles, coloured by speed
- ``signals/<name>``                        Scalars; ``name`` may contain ``/`` to group signals
- ``events/phase``                          TextLog of the controller's phase changes

Timelines: ``sim_time`` (duration, simulated seconds) and ``step`` (sequence, simulation step index).
Names are split on ``/`` and each part escaped, so any body, geom or signal name gives a valid path.
"""

from __future__ import annotations

import rerun as rr

TIMELINE_TIME = "sim_time"
TIMELINE_STEP = "step"

WORLD = "world"
ROBOT = "world/robot"
LIQUID = "world/liquid"
SIGNALS = "signals"
EVENTS = "events"
PHASE = "events/phase"


def _join(*parts: str) -> str:
    return "/".join(rr.escape_entity_path_part(p) for p in parts)


def body_path(body: str) -> str:
    """Entity of a MuJoCo body (its name is one path part, escaped)."""
    return f"{ROBOT}/{_join(body)}"


def geom_path(body: str, geom: str) -> str:
    """Entity of a geom under its body."""
    return f"{body_path(body)}/{_join(geom)}"


def signal_parts(name: str) -> list[str]:
    """The non-empty ``/``-separated parts of a signal name; ValueError for a name with none."""
    parts = [p for p in name.split("/") if p]
    if not parts:
        raise ValueError(f"signal name {name!r} has no path part")
    return parts


def signal_path(name: str) -> str:
    """Entity of a scalar signal: ``signals/<name>``, ``/`` in ``name`` separating path parts."""
    return f"{SIGNALS}/{_join(*signal_parts(name))}"


def absolute(path: str) -> str:
    """The form Rerun reports entity paths in when reading a recording back (leading ``/``)."""
    return path if path.startswith("/") else "/" + path
