"""The Rerun recording of a pour (``pour.rrd``): what the coupling loop calls while it runs.

Usage::

    with PourRecorder(run_dir / "pour.rrd", model, RecordingConfig(), particle_radius=spacing / 2) as rec:
        for step ...:
            rec.log_scalars(t, step, {"pourer/theta": theta, "volume/in_pourer": v})
            if rec.state_due(t):                      # skip the device -> host copy when nothing will be logged
                rec.log_state(t, step, data, positions, speeds, active=active)
            if phase_changed:
                rec.log_phase(t, step, phase, reason)

Entity paths and timelines are listed in :mod:`cosim.io.rerun_paths`; every 3-D quantity is in the MuJoCo world
frame (m, z up). The static geometry (:mod:`cosim.io.rerun_geometry`) is logged once, at construction. Scalars and
body poses are buffered and sent as columns (``send_columns``) every :data:`FLUSH_ROWS` rows and at
:meth:`PourRecorder.close`; particles are logged as they come. The default blueprint
(:mod:`cosim.io.rerun_blueprint`) is built at close, when every signal name is known.

The file is written to a hidden temporary file beside ``path`` and moved onto ``path`` (``os.replace``) by
:meth:`PourRecorder.close`; :meth:`PourRecorder.abort` (or an exception inside ``with``) deletes it, so ``path``
either holds a complete recording or nothing. Each recorder owns its own ``rr.RecordingStream``: several may live
in one process.
"""

from __future__ import annotations

import math
import os
import uuid
from collections.abc import Mapping
from pathlib import Path

import mujoco
import numpy as np
import rerun as rr
from matplotlib import colormaps

from cosim.checks import check_positive
from cosim.errors import InputError
from cosim.io import rerun_paths
from cosim.io.rerun_blueprint import build_blueprint, series_label
from cosim.io.recording_config import RecordingConfig
from cosim.io.rerun_geometry import body_name, geom_visuals, log_static_geometry, xyzw_from_wxyz

# Buffered rows per entity before they are sent as one column batch (bounds memory; 1000 rows of 30 signals
# is ~0.7 MB of Python floats).
FLUSH_ROWS = 1000
# Matplotlib colormap of the particle speed, from 0 (bottom) to RecordingConfig.speed_color_max (top).
SPEED_COLORMAP = "viridis"
# Fraction of a logging period by which a state may come early and still count for its slot (absorbs the
# rounding of sim_time = step * dt).
_SLOT_TOLERANCE = 1e-6


class _Columns:
    """Rows buffered for one entity: times (ns), steps, and one value row per call."""

    __slots__ = ("time_ns", "steps", "rows")

    def __init__(self) -> None:
        self.time_ns: list[int] = []
        self.steps: list[int] = []
        self.rows: list = []

    def append(self, time_ns: int, step: int, row) -> None:
        self.time_ns.append(time_ns)
        self.steps.append(step)
        self.rows.append(row)

    def __len__(self) -> int:
        return len(self.rows)

    def indexes(self) -> list[rr.TimeColumn]:
        return [
            rr.TimeColumn(rerun_paths.TIMELINE_TIME, duration=np.asarray(self.time_ns, dtype="timedelta64[ns]")),
            rr.TimeColumn(rerun_paths.TIMELINE_STEP, sequence=np.asarray(self.steps, dtype=np.int64)),
        ]

    def clear(self) -> None:
        self.time_ns.clear()
        self.steps.clear()
        self.rows.clear()


def _time_ns(sim_time: float) -> int:
    """Simulated time (s) as integer nanoseconds, the resolution of Rerun's duration timeline."""
    return int(round(float(sim_time) * 1e9))


class PourRecorder:
    """Writes one pour to a ``.rrd`` file.

    path: where the finished recording goes (its folder must exist; an existing file there is replaced at close).
    model: the MuJoCo model whose visible geoms are drawn (groups 0-2, see :mod:`cosim.io.rerun_geometry`).
    config: :class:`RecordingConfig`.
    particle_radius: m, drawn radius of a liquid particle (e.g. half the particle spacing). (0, 0.1]
    application_id: Rerun application id (the viewer groups recordings by it).
    """

    def __init__(
        self,
        path: str | os.PathLike,
        model: mujoco.MjModel,
        config: RecordingConfig = RecordingConfig(),
        *,
        particle_radius: float = 0.0025,
        application_id: str = "cosim",
    ) -> None:
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise InputError(f"recording path {self.path}: folder {self.path.parent} does not exist")
        self.config = config
        self.particle_radius = check_positive("recording.particle_radius", particle_radius, "m", 0.1)
        self._tmp = self.path.with_name(f".{self.path.name}.{uuid.uuid4().hex}.part")
        self._rec = rr.RecordingStream(application_id)
        self._rec.set_log_time_enabled(False)  # only sim_time and step: the recording is a function of the run
        self._rec.set_log_tick_enabled(False)
        self._rec.save(self._tmp)
        self._open = True
        try:
            visuals, self.skipped_geoms = geom_visuals(model)
            log_static_geometry(self._rec, visuals)
        except BaseException:
            self.abort()
            raise
        # Bodies that carry drawn geometry move; the world body (0) is the world frame itself.
        self._bodies = np.array(sorted({v.body_id for v in visuals if v.body_id != 0}), dtype=np.int64)
        self._body_paths = [rerun_paths.body_path(body_name(model, int(b))) for b in self._bodies]
        self._poses = _Columns()
        self._signals: dict[str, _Columns] = {}
        self._signal_paths: dict[str, str] = {}
        self._last_slot: int | None = None
        self._cmap = colormaps[SPEED_COLORMAP]

    # ---- logging -------------------------------------------------------------------------------------------
    def state_due(self, sim_time: float) -> bool:
        """Whether :meth:`log_state` at ``sim_time`` (s) would log (one state per 1/particle_rate_hz slot)."""
        return self._last_slot is None or self._slot(sim_time) > self._last_slot

    def log_state(
        self,
        sim_time: float,
        step: int,
        data: mujoco.MjData,
        particles: np.ndarray | None = None,
        speeds: np.ndarray | None = None,
        *,
        active: np.ndarray | None = None,
        force: bool = False,
    ) -> bool:
        """Log body poses and liquid particles, at most once per 1/particle_rate_hz of simulated time.

        sim_time: s. step: simulation step index. data: MjData after mj_forward/mj_step (``xpos`` m and ``xquat``
        [w, x, y, z], body -> world). particles: (N, 3) m, world frame. speeds: (N,) m/s (colour; None: the colour
        map's bottom colour). active: (N,) bool, False for particles that left the simulation (not drawn).
        Decimation picks every particle_stride-th particle index before the active mask.
        force: log even if this rate slot was already logged (e.g. the final state).
        Returns whether it logged.
        """
        self._check_open()
        if not (force or self.state_due(sim_time)):
            return False
        slot = self._slot(sim_time)
        self._last_slot = slot if self._last_slot is None else max(slot, self._last_slot)
        t_ns, step = _time_ns(sim_time), int(step)
        if len(self._bodies):
            self._poses.append(
                t_ns, step, (np.array(data.xpos[self._bodies]), xyzw_from_wxyz(data.xquat[self._bodies]))
            )
            if len(self._poses) >= FLUSH_ROWS:
                self._send_poses()
        if particles is not None:
            self._log_particles(t_ns, step, particles, speeds, active)
        return True

    def log_scalars(self, sim_time: float, step: int, values: Mapping[str, float]) -> None:
        """Log scalar signals at ``signals/<name>`` (every call; buffered).

        values: name -> value (float). ``/`` in a name groups signals: see :mod:`cosim.io.rerun_blueprint` for how
        names map to plot panels (e.g. ``pourer/theta``, ``volume/in_pourer``, ``joints/pour_arm/elbow.pos``).
        """
        self._check_open()
        t_ns, step = _time_ns(sim_time), int(step)
        for name, value in values.items():
            columns = self._signals.get(name)
            if columns is None:
                columns = self._add_signal(name)
            columns.append(t_ns, step, float(value))
            if len(columns) >= FLUSH_ROWS:
                self._send_signal(name)

    def log_phase(self, sim_time: float, step: int, phase: str, reason: str = "") -> None:
        """Log a controller phase change as a text line ``<phase>: <reason>`` at ``events/phase``."""
        self._check_open()
        self._set_time(_time_ns(sim_time), int(step))
        self._rec.log(rerun_paths.PHASE, rr.TextLog(f"{phase}: {reason}" if reason else str(phase), level=rr.TextLogLevel.INFO))

    # ---- finishing -----------------------------------------------------------------------------------------
    def close(self) -> Path:
        """Send what is buffered and the default blueprint, close the file and move it onto ``path``. Idempotent."""
        if not self._open:
            return self.path
        try:
            self._send_poses()
            for name in self._signals:
                self._send_signal(name)
            self._rec.send_blueprint(build_blueprint(self._signals))
            self._rec.flush()
            self._rec.disconnect()
            self._open = False
            os.replace(self._tmp, self.path)
        except BaseException:
            self.abort()
            raise
        return self.path

    def abort(self) -> None:
        """Stop recording and delete the partial file: nothing is left at ``path`` (or beside it)."""
        self._open = False
        self._rec.disconnect()
        self._tmp.unlink(missing_ok=True)

    def __enter__(self) -> "PourRecorder":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()

    # ---- internals -----------------------------------------------------------------------------------------
    def _check_open(self) -> None:
        if not self._open:
            raise RuntimeError(f"recording {self.path} is closed")

    def _slot(self, sim_time: float) -> int:
        return math.floor(float(sim_time) * self.config.particle_rate_hz + _SLOT_TOLERANCE)

    def _set_time(self, t_ns: int, step: int) -> None:
        self._rec.set_time(rerun_paths.TIMELINE_TIME, duration=np.timedelta64(t_ns, "ns"))
        self._rec.set_time(rerun_paths.TIMELINE_STEP, sequence=step)

    def _add_signal(self, name: str) -> _Columns:
        path = rerun_paths.signal_path(name)
        self._rec.log(path, rr.SeriesLines(names=series_label(name)), static=True)
        self._signal_paths[name] = path
        self._signals[name] = columns = _Columns()
        return columns

    def _send_signal(self, name: str) -> None:
        columns = self._signals[name]
        if len(columns):
            self._rec.send_columns(
                self._signal_paths[name],
                indexes=columns.indexes(),
                columns=rr.Scalars.columns(scalars=np.asarray(columns.rows, dtype=np.float64)),
            )
            columns.clear()

    def _send_poses(self) -> None:
        if not len(self._poses):
            return
        indexes = self._poses.indexes()
        positions = np.stack([row[0] for row in self._poses.rows], axis=1)  # (bodies, rows, 3)
        quats = np.stack([row[1] for row in self._poses.rows], axis=1)  # (bodies, rows, 4) xyzw
        for k, path in enumerate(self._body_paths):
            self._rec.send_columns(path, indexes=indexes, columns=rr.Transform3D.columns(translation=positions[k], quaternion=quats[k]))
        self._poses.clear()

    def _log_particles(self, t_ns: int, step: int, particles, speeds, active) -> None:
        positions = np.asarray(particles)
        n = len(positions)
        if positions.ndim != 2 or positions.shape[1] != 3:
            raise ValueError(f"particles: expected shape (N, 3), got {positions.shape}")
        for label, arr in (("speeds", speeds), ("active", active)):
            if arr is not None and np.shape(arr) != (n,):
                raise ValueError(f"{label}: expected shape ({n},), got {np.shape(arr)}")
        index = np.arange(0, n, self.config.particle_stride)
        if active is not None:
            index = index[np.asarray(active, dtype=bool)[index]]
        level = np.zeros(len(index)) if speeds is None else np.asarray(speeds)[index] / self.config.speed_color_max
        colors = self._cmap(np.clip(level, 0.0, 1.0), bytes=True)
        self._set_time(t_ns, step)
        self._rec.log(
            rerun_paths.LIQUID,
            rr.Points3D(positions[index].astype(np.float32), colors=colors, radii=self.particle_radius),
        )
