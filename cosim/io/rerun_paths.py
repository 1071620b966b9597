"""Entity paths and timelines of a cosim Rerun recording: the one place that names them.

Layout of a recording (all 3-D data in the MuJoCo world frame: metres, z up):

- ``world``                                 view coordinates (right-handed, z up), static
- ``world/scene/<geom>``                    static geoms of MuJoCo's world body (the table)
- ``world/robot/<body>``                    Transform3D body -> world, on the timelines (bodies that carry a
                                              drawn geom); a body named ``pour_arm/wrist_1_link`` is the entity
                                              ``world/robot/pour_arm/wrist_1_link``
- ``world/robot/<body>/<geom>``             static Transform3D geom -> body plus the geom's shape
- ``world/frames/<site>``                   Transform3D of a tool frame (site -> world) drawn as axes
- ``world/liquid``                          Points3D of the (decimated) liquid particles, coloured by speed
- ``world/liquid_force``                    Arrows3D, the liquid's force on each vessel, from its centre of mass
- ``world/landing/predicted|measured``      Points3D, where the stream lands at the catcher's rim height
- ``world/lip_path/commanded``              LineStrips3D, the lip's commanded path over the whole pour (static)
- ``signals/<group>/<quantity>_<unit>``     Scalars, one series per name part of the logged mapping
- ``events/phase``                          TextLog of the controller's phases and its state while it pours
- ``legend``                                TextDocument: the liquid's colour scale and how the liquid is drawn

Timelines: ``sim_time`` (duration, simulated seconds) and ``step`` (sequence, simulation step index).
Every name part is cleaned to letters, digits, ``_``, ``-`` and ``.`` (others become ``_``), so paths need no
escapes; MuJoCo's ``/`` in body names separates path parts.
"""

from __future__ import annotations

import re

TIMELINE_TIME = "sim_time"
TIMELINE_STEP = "step"

WORLD = "world"
SCENE = "world/scene"
ROBOT = "world/robot"
FRAMES = "world/frames"
LIQUID = "world/liquid"
LIQUID_FORCE = "world/liquid_force"
LANDING = "world/landing"
LIP_PATH = "world/lip_path"
SIGNALS = "signals"
EVENTS = "events"
PHASE = "events/phase"
LEGEND = "legend"

_NOT_PLAIN = re.compile(r"[^A-Za-z0-9_.-]+")


def name_parts(name: str) -> list[str]:
    """The non-empty ``/``-separated parts of a name, each cleaned (see the module docstring); ValueError for a name
    with none."""
    parts = [_NOT_PLAIN.sub("_", p) for p in name.split("/") if p.strip()]
    if not parts:
        raise ValueError(f"name {name!r} has no path part")
    return parts


def under(root: str, name: str) -> str:
    """Entity ``root/<name>``, ``/`` in ``name`` separating path parts."""
    return "/".join([root, *name_parts(name)])


def signal_path(name: str) -> str:
    """Entity of a scalar signal: ``signals/<name>``."""
    return under(SIGNALS, name)


def absolute(path: str) -> str:
    """The form Rerun reports entity paths in when reading a recording back (leading ``/``)."""
    return path if path.startswith("/") else "/" + path
