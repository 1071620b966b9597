"""The checks of cosim's own kinds of values (a device, a ROS 2 name), and the generic checks of
:mod:`declared_settings.checks`, which every cosim layer imports from here.

Every check raises :class:`cosim.errors.InputError` with one line that names the field, the allowed range and
the value that was given, e.g. ``scene.device: must be 'cpu', 'cuda' or 'cuda:N', got 'gpu'``.
"""

from __future__ import annotations

import re

from declared_settings.checks import (  # noqa: F401 (the generic checks, imported by cosim's layers from here)
    check_choice, check_int, check_number, check_range, check_vector, value_text,
)
from cosim.errors import InputError

# A ROS 2 name token (e.g. a tf prefix): a letter, then letters, digits and underscores; at most this long.
ROS_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
ROS_NAME_MAX = 64


def check_positive(field: str, value: object, unit: str = "", hi: float | None = None) -> float:
    """Check ``0 < value (<= hi)``."""
    return check_range(field, value, 0.0, hi, unit, lo_open=True)


def check_device(field: str, value: object) -> str:
    """A warp device name: 'cpu', 'cuda' or 'cuda:N' (availability is checked when the device is opened)."""
    if isinstance(value, str) and (value in ("cpu", "cuda") or (value.startswith("cuda:") and value[5:].isdigit())):
        return value
    raise InputError(f"{field}: must be 'cpu', 'cuda' or 'cuda:N', got {value_text(value)}")


def check_ros_name(field: str, value: object, allow_empty: bool = False) -> str:
    """A ROS 2 name token (e.g. a tf prefix): a letter, then letters, digits or '_', at most :data:`ROS_NAME_MAX`
    characters; ``''`` too where ``allow_empty``."""
    if isinstance(value, str) and ((value == "" and allow_empty) or (ROS_NAME.fullmatch(value) and len(value) <= ROS_NAME_MAX)):
        return value
    empty = " or ''" if allow_empty else ""
    raise InputError(
        f"{field}: must be a letter followed by letters, digits or '_' (at most {ROS_NAME_MAX} characters){empty}, "
        f"got {value_text(value)}"
    )
