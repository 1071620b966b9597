"""Read a finished cosim recording back (``rerun.chunk.RrdReader``), for tests and for checks on a run's outputs.

Entity paths are reported as Rerun writes them: absolute (``/signals/pour/tilt_deg``). Times are in seconds of simulated time (the ``sim_time`` timeline), steps are the
``step`` timeline. Rows come back sorted by sim_time, then step, then logging order.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
import pyarrow as pa
from rerun.chunk import RrdReader

from cosim.io import rerun_paths

# Rerun's own entity for recording properties; not part of the pour.
_PROPERTIES_ENTITY = "/__properties"
_ROW_ID = "rerun.controls.RowId"


@dataclass(frozen=True)
class Rows:
    """The rows of one component of one entity.

    sim_time: (n,) s, or None for static data. step: (n,) int64, or None for static data.
    values: per row, the component batch as a numpy array (e.g. (k, 3) for k positions, (1,) for a scalar).
    """

    sim_time: np.ndarray | None
    step: np.ndarray | None
    values: list[np.ndarray]


@dataclass(frozen=True)
class ScalarSeries:
    """One series of a scalar signal: sim_time (n,) s, step (n,) int64, values (n,) float64."""

    sim_time: np.ndarray
    step: np.ndarray
    values: np.ndarray


def entity_paths(path: str | os.PathLike) -> set[str]:
    """Every entity path of the recording (its first recording store), without Rerun's property entity."""
    schema = RrdReader(path).store().schema()
    return {str(p) for p in schema.entity_paths()} - {_PROPERTIES_ENTITY}


def recording_properties(path: str | os.PathLike) -> dict[str, object]:
    """The properties a recorder sent with the recording (``PourRecorder(properties=...)``): name -> value."""
    out: dict[str, object] = {}
    for chunk in RrdReader(path).store().stream().filter(content=f"{_PROPERTIES_ENTITY}/**"):
        batch = chunk.to_record_batch()
        for name in batch.schema.names:
            if name != _ROW_ID and chunk.entity_path != _PROPERTIES_ENTITY:
                out[name.rsplit(":", 1)[-1]] = batch.column(name).to_pylist()[-1][0]
    return out


def blueprint_camera(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """(eye position, look target) (3,) m of the 3-D view in the recording's default blueprint; KeyError if it
    sets none."""
    reader = RrdReader(path)
    for entry in reader.blueprints():
        for chunk in reader.store(store=entry).stream():
            batch = chunk.to_record_batch()
            if "EyeControls3D:position" in batch.schema.names:
                eye = batch.column("EyeControls3D:position").to_pylist()[-1][0]
                target = batch.column("EyeControls3D:look_target").to_pylist()[-1][0]
                return np.array(eye), np.array(target)
    raise KeyError(f"{path}: the blueprint sets no 3-D eye position")


def _batch_numpy(arr: pa.Array) -> np.ndarray:
    """One component batch (the inside of a row) as numpy: fixed-size lists become a 2-D array."""
    if pa.types.is_fixed_size_list(arr.type):
        return arr.flatten().to_numpy(zero_copy_only=False).reshape(len(arr), arr.type.list_size)
    if pa.types.is_string(arr.type) or pa.types.is_large_string(arr.type):
        return np.array(arr.to_pylist(), dtype=object)
    return arr.to_numpy(zero_copy_only=False)


def read_component(path: str | os.PathLike, entity: str, component: str) -> Rows:
    """All rows of ``component`` (e.g. ``"Scalars:scalars"``, ``"Points3D:positions"``) logged at ``entity``.

    entity: a path as the recorder names it (``signals/pourer/theta``) or as read back (leading ``/``).
    Static rows and temporal rows are not mixed: if the entity has static rows of the component, those are
    returned (sim_time and step None), else the temporal rows.
    """
    target = rerun_paths.absolute(entity)
    static_rows: list[np.ndarray] = []
    times, steps, row_ids, values = [], [], [], []
    for chunk in RrdReader(path).store().stream().filter(content=target):  # a bare path selects only itself
        batch = chunk.to_record_batch()
        if component not in batch.schema.names:
            continue
        column = batch.column(component)
        present = np.flatnonzero(column.is_valid().to_numpy(zero_copy_only=False))
        rows = [_batch_numpy(column[int(i)].values) for i in present]
        if chunk.is_static:
            static_rows.extend(rows)
            continue
        times.append(batch.column(rerun_paths.TIMELINE_TIME).cast(pa.int64()).to_numpy()[present])
        steps.append(batch.column(rerun_paths.TIMELINE_STEP).to_numpy()[present])
        row_ids.append(np.array(batch.column(_ROW_ID).to_pylist(), dtype="S16")[present])
        values.extend(rows)
    if static_rows:
        return Rows(None, None, static_rows)
    if not values:
        raise KeyError(f"{path}: no {component} logged at {target}")
    t_ns, step, row_id = (np.concatenate(a) for a in (times, steps, row_ids))
    order = np.lexsort((row_id, step, t_ns))
    return Rows(t_ns[order] / 1e9, step[order].astype(np.int64), [values[i] for i in order])


def series_names(path: str | os.PathLike, name: str) -> list[str]:
    """The series names of the scalar signal ``name`` (its ``SeriesLines`` names, in logging order)."""
    return [str(v) for v in read_component(path, rerun_paths.signal_path(name), "SeriesLines:names").values[0]]


def read_scalar_series(path: str | os.PathLike, name: str, series: str | None = None) -> ScalarSeries:
    """The scalar signal ``name`` (as passed to ``PourRecorder.log_scalars``) read back from the recording; for a
    signal with several series, the one named ``series`` (KeyError if it has no such series)."""
    rows = read_component(path, rerun_paths.signal_path(name), "Scalars:scalars")
    k = 0
    if series is not None:
        names = series_names(path, name)
        if series not in names:
            raise KeyError(f"{path}: signal {name} has no series {series!r} (it has {names})")
        k = names.index(series)
    values = np.array([float(r[k]) for r in rows.values], dtype=np.float64)
    return ScalarSeries(rows.sim_time, rows.step, values)
