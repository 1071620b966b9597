"""The sweep file: a base scene, axes over scene keys, and how the axes combine.

A sweep file is TOML::

    scene = "my_cell.toml"        # the base scene: a scene file (relative to this file), or a [scene] table
    mode = "grid"                 # 'grid': every combination of the axes' values; 'sample': `samples` random points
    samples = 12                  # mode 'sample' only: how many pours
    seed = 0                      # seeds every random draw (a uniform axis's values, the sample points)

    [axes]                        # dotted scene keys; each axis one of:
    "liquid.fill_depth" = [0.08, 0.12, 0.16]                          # a list of values
    "fluid.particles_across" = { start = 16, stop = 32, num = 3 }     # a range: num evenly spaced, both ends included
    "liquid.pour_fraction" = { uniform = [0.3, 0.9], samples = 4 }   # random, uniform in [lo, hi)

In mode 'sample' a uniform axis takes no ``samples`` (each point draws its own value) and a list or range axis
contributes one of its values, drawn uniformly. Keys must name a value of the scene (``cosim scene --dump`` lists
them); a value a scene refuses fails that pour only, recorded with its error, not the sweep.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cosim.config_mapping import read_toml_file
from cosim.errors import InputError
from declared_settings.setting import argument

MODES = ("grid", "sample")
MAX_POURS = 100_000  # more pours than any cluster runs in one sweep: a typo (a range's num) is refused early
TOP_LEVEL_KEYS = ("scene", "mode", "samples", "seed", "axes")
RANGE_DIGITS = 12  # significant digits of a range's float values: clears linspace's last-bit noise
SWEEP = "sweep"
SEED = argument(SWEEP, "Seeds every random draw (a uniform axis's values, the sample points).", "", 0, 2**63 - 1,
                kind="int")
# a count of pours or of an axis's values: mode 'sample''s samples, a range's num, a uniform axis's samples
POURS = argument(SWEEP, "How many pours (or an axis's values).", "", 1, MAX_POURS, kind="int")


@dataclass(frozen=True)
class Axis:
    """One swept scene key.

    key: dotted scene key, e.g. 'liquid.fill_depth'.
    values: the values it takes (a list, a range, or a uniform axis's draws in mode 'grid'); None for a uniform axis
      in mode 'sample'.
    interval: (lo, hi) of a uniform axis, else None.
    """

    key: str
    values: tuple | None
    interval: tuple[float, float] | None = None


@dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep file.

    name: the sweep's name (the file's stem), for its default output folder.
    base: the base scene as a TOML table (axes override its keys).
    base_path: the base scene's file, or None for an inline [scene] table (the pours are then named 'seed-pour').
    axes: the swept keys, in the file's order.
    mode: 'grid' or 'sample'.
    samples: pours drawn in mode 'sample' (0 in mode 'grid').
    seed: :data:`SEED`.
    """

    name: str
    base: dict
    base_path: Path | None
    axes: tuple[Axis, ...]
    mode: str
    samples: int
    seed: int


def check_scene_key(key: str) -> None:
    """Refuse ``key`` unless it names a value of the pour scene (a leaf field of :class:`cosim.pour_scene.PourScene`,
    or a key inside one of its tables such as ``trajectory.limits``)."""
    from cosim.pour_scene import PourScene

    cls: Any = PourScene
    parts = key.split(".")
    for depth, part in enumerate(parts):
        names = {f.name for f in dataclasses.fields(cls)}
        where = ".".join(parts[:depth]) or "the scene"
        if part not in names:
            raise InputError(f"axes.{key}: {part!r} is not a key of {where} (keys there: {', '.join(sorted(names))})")
        tp = typing.get_type_hints(cls)[part]
        if typing.get_origin(tp) in (typing.Union, types.UnionType):
            tp = next(a for a in typing.get_args(tp) if a is not type(None))
        if typing.get_origin(tp) is dict:
            if depth == len(parts) - 1:
                raise InputError(f"axes.{key}: a table of the scene, not a value (sweep one of its keys)")
            return
        if dataclasses.is_dataclass(tp):
            if depth == len(parts) - 1:
                raise InputError(f"axes.{key}: a section of the scene, not a value (sweep one of its keys)")
            cls = tp
        elif depth < len(parts) - 1:
            raise InputError(f"axes.{key}: {'.'.join(parts[:depth + 1])} is a value, it has no keys")


def _number(field: str, value: Any) -> float | int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{field}: must be a finite number, got {value!r}")
    return value


def _range_values(field: str, table: dict) -> tuple:
    """``num`` evenly spaced values from ``start`` to ``stop``, both included; integers where both ends are integers
    and every step is a whole number (a range of particle counts stays a range of integers), else floats rounded to
    :data:`RANGE_DIGITS` significant digits (0.11, not 0.11000000000000001, as a user would write it)."""
    start, stop = _number(f"{field}.start", table["start"]), _number(f"{field}.stop", table["stop"])
    num = POURS.check(f"{field}.num", table["num"])
    if not math.isfinite(float(stop) - float(start)):  # the evenly spaced values need the width itself finite
        raise InputError(f"{field}: stop - start must be a finite number, got {start:g} to {stop:g}")
    if num == 1:
        return (start,)
    if isinstance(start, int) and isinstance(stop, int) and (stop - start) % (num - 1) == 0:
        step = (stop - start) // (num - 1)
        return tuple(start + k * step for k in range(num))
    import numpy as np

    return tuple(float(f"{v:.{RANGE_DIGITS}g}") for v in np.linspace(start, stop, num))


def _uniform_interval(field: str, bounds: Any) -> tuple[float, float]:
    if not isinstance(bounds, list) or len(bounds) != 2:
        raise InputError(f"{field}.uniform: must be [lo, hi], got {bounds!r}")
    lo, hi = (float(_number(f"{field}.uniform[{k}]", b)) for k, b in enumerate(bounds))
    if not lo < hi:
        raise InputError(f"{field}.uniform: lo must be below hi, got [{lo:g}, {hi:g}]")
    if not math.isfinite(hi - lo):  # numpy's draw needs the width itself finite
        raise InputError(f"{field}.uniform: hi - lo must be a finite number, got [{lo:g}, {hi:g}]")
    return lo, hi


def parse_axis(key: str, value: Any, mode: str, seed: int, index: int) -> Axis:
    """One ``[axes]`` entry (module docstring); a uniform axis in mode 'grid' draws its ``samples`` values with a
    generator seeded by (``seed``, ``index``), so adding an axis leaves the others' draws alone."""
    field = f"axes.{key}"
    check_scene_key(key)
    if isinstance(value, list):
        if not value:
            raise InputError(f"{field}: an empty list (give at least one value)")
        return Axis(key, tuple(value))
    if not isinstance(value, dict):
        raise InputError(f"{field}: must be a list of values, a range {{start, stop, num}} or {{uniform = [lo, hi]}}, "
                         f"got {value!r}")
    if set(value) == {"start", "stop", "num"}:
        return Axis(key, _range_values(field, value))
    if "uniform" in value and set(value) <= {"uniform", "samples"}:
        interval = _uniform_interval(field, value["uniform"])
        if mode == "sample":
            if "samples" in value:
                raise InputError(f"{field}.samples: only in mode 'grid' (in mode 'sample' each pour draws its own value)")
            return Axis(key, None, interval)
        if "samples" not in value:
            raise InputError(f"{field}.samples: a uniform axis in mode 'grid' needs its number of values, in {POURS.allowed()}")
        count = POURS.check(f"{field}.samples", value["samples"])
        import numpy as np

        draws = np.random.default_rng([seed, index]).uniform(*interval, size=count)
        return Axis(key, tuple(float(v) for v in draws), interval)
    raise InputError(f"{field}: a table must be {{start, stop, num}} or {{uniform = [lo, hi], samples = N}}, "
                     f"got keys {', '.join(sorted(value))}")


def _base_scene(value: Any, folder: Path) -> tuple[dict, Path | None]:
    """The base scene's table and its file (None for an inline table)."""
    if isinstance(value, dict):
        return value, None
    if not isinstance(value, str):
        raise InputError(f"scene: must be a scene file's path or a [scene] table, got {value!r}")
    path = folder / value
    try:
        return read_toml_file(path, "scene file"), path
    except InputError as exc:
        raise InputError(f"scene: {exc}") from None


def parse_sweep(table: dict, folder: Path, name: str) -> SweepSpec:
    """A sweep from its TOML ``table`` (a scene path in it is relative to ``folder``); InputError names the key."""
    unknown = sorted(set(table) - set(TOP_LEVEL_KEYS))
    if unknown:
        raise InputError(f"{unknown[0]}: unknown key (known keys: {', '.join(TOP_LEVEL_KEYS)})")
    base, base_path = _base_scene(table.get("scene", {}), folder)
    mode = table.get("mode", "grid")
    if mode not in MODES:
        raise InputError(f"mode: must be one of {', '.join(map(repr, MODES))}, got {mode!r}")
    seed = SEED.check("seed", table.get("seed", 0))
    if mode == "grid" and "samples" in table:
        raise InputError("samples: only in mode 'sample' (mode 'grid' runs every combination of the axes)")
    if mode == "sample" and "samples" not in table:
        raise InputError(f"samples: mode 'sample' needs the number of pours, in {POURS.allowed()}")
    samples = POURS.check("samples", table["samples"]) if mode == "sample" else 0
    axes_table = table.get("axes")
    if not isinstance(axes_table, dict) or not axes_table:
        raise InputError("axes: needs at least one axis, e.g. [axes] \"liquid.fill_depth\" = [0.08, 0.12]")
    axes = tuple(parse_axis(key, value, mode, seed, k) for k, (key, value) in enumerate(axes_table.items()))
    if mode == "grid" and math.prod(len(a.values) for a in axes) > MAX_POURS:
        raise InputError(f"axes: the grid has {math.prod(len(a.values) for a in axes):,} pours, over the {MAX_POURS:,} "
                         f"a sweep runs (fewer values, or mode = 'sample')")
    return SweepSpec(name, base, base_path, axes, mode, samples, seed)


def load_sweep(path: str | Path) -> SweepSpec:
    """Read a sweep file; any problem is one InputError line naming the file and the key."""
    path = Path(path)
    table = read_toml_file(path, "sweep file")
    try:
        return parse_sweep(table, path.parent, path.stem)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
