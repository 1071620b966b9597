"""The Rerun recording of a pour (``pour.rrd``): what the coupling loop calls while it runs.

Usage::

    with PourRecorder(run_dir / "pour.rrd", model, RecordingConfig(), particle_radius=spacing / 2,
                      name="seed-pour", properties={"scene": scene_toml}, frames=("pourer/frame",)) as rec:
        for step ...:
            rec.log_scalars(t, step, {"pour/tilt_deg": {"commanded": 40.1, "measured": 39.8}, "pour/head_mm": 4.2})
            if rec.state_due(t):                      # skip the device -> host copy when nothing will be logged
                rec.log_state(t, step, data, positions, speeds, active=active)
                rec.log_arrows(t, step, "liquid_force/pourer", origins, vectors)
            if phase_changed:
                rec.log_text(t, step, f"{phase}: {reason}")

Entity paths and timelines are listed in :mod:`cosim.io.rerun_paths`; every 3-D quantity is in the MuJoCo world
frame (m, z up). The static geometry (:mod:`cosim.io.rerun_geometry`) is logged once, at construction.

Everything on the timelines is buffered per entity and sent as columns (``send_columns``): one chunk per entity and
:data:`FLUSH_BYTES` of data, so that a viewer loads a few large chunks rather than one per logged row. The default
blueprint (:mod:`cosim.io.rerun_blueprint`) is built at close, when every signal name is known.

The file is written to a hidden temporary file beside ``path`` and moved onto ``path`` (``os.replace``) by
:meth:`PourRecorder.close`; :meth:`PourRecorder.abort` (or an exception inside ``with``) deletes it, so ``path``
either holds a complete recording or nothing. Each recorder owns its own ``rr.RecordingStream``: several may live
in one process.
"""

from __future__ import annotations

import math
import os
import uuid
from collections.abc import Mapping, Sequence
from pathlib import Path

import mujoco
import numpy as np
import rerun as rr
from matplotlib import colormaps

from cosim.errors import InputError
from cosim.io import rerun_paths
from cosim.io.rerun_blueprint import Camera, build_blueprint, colour_scale_text
from cosim.io.recording_config import RECORDING, RecordingConfig
from cosim.io.rerun_geometry import body_paths, geom_visuals, log_static_geometry, xyzw_from_wxyz
from declared_settings.setting import argument

# Bytes of buffered data per entity before it is sent as one chunk (bounds memory; a 2-D pour's particles fill
# one chunk in about a minute of simulated time at 30 Hz, its scalars never do).
FLUSH_BYTES = 32 * 2**20
# The drawn particles' size, given by the run that records.
PARTICLE_RADIUS = argument(RECORDING, "Drawn radius of a liquid particle (e.g. half the particle spacing).", "m",
                           0.0, 0.1, lo_open=True)
# Matplotlib colormap of the particle speed, from 0 (bottom) to RecordingConfig.speed_color_max (top).
SPEED_COLORMAP = "viridis"
# Matplotlib colormap the series of one plot take their colours from (up to 10 distinct ones).
SERIES_COLORMAP = "tab10"
# m: length of the drawn axes of a tool frame.
FRAME_AXIS_LENGTH = 0.08
# Fraction of a logging period by which a state may come early and still count for its slot (absorbs the
# rounding of sim_time = step * dt).
_SLOT_TOLERANCE = 1e-6


class _Columns:
    """Rows buffered for one entity of one archetype: times (ns), steps, and per row one batch of each component
    (arrays of equal length k, the row's instance count). A row keeps copies of its batches: a caller's arrays may
    change after it has logged them (a view into MuJoCo's ``data.xpos`` moves with the next step)."""

    __slots__ = ("archetype", "time_ns", "steps", "lengths", "components", "nbytes")

    def __init__(self, archetype) -> None:
        self.archetype = archetype
        self.time_ns: list[int] = []
        self.steps: list[int] = []
        self.lengths: list[int] = []
        self.components: dict[str, list] = {}
        self.nbytes = 0

    def append(self, time_ns: int, step: int, **batches) -> None:
        k = None
        for name, batch in batches.items():
            batch = np.array(batch) if not isinstance(batch, list) else list(batch)
            k = len(batch) if k is None else k
            if len(batch) != k:
                raise ValueError(f"{name}: expected {k} instances, got {len(batch)}")
            self.components.setdefault(name, []).append(batch)
            self.nbytes += getattr(batch, "nbytes", 64 * len(batch))
        self.time_ns.append(time_ns)
        self.steps.append(step)
        self.lengths.append(k or 0)

    def __len__(self) -> int:
        return len(self.lengths)

    def send(self, rec: rr.RecordingStream, entity: str) -> None:
        """Send the buffered rows as one chunk and empty the buffer."""
        if not self.lengths:
            return
        indexes = [
            rr.TimeColumn(rerun_paths.TIMELINE_TIME, duration=np.asarray(self.time_ns, dtype="timedelta64[ns]")),
            rr.TimeColumn(rerun_paths.TIMELINE_STEP, sequence=np.asarray(self.steps, dtype=np.int64)),
        ]
        joined = {
            name: ([x for row in rows for x in row] if isinstance(rows[0], list) else np.concatenate(rows))
            for name, rows in self.components.items()
        }
        columns = self.archetype.columns(**joined).partition(np.asarray(self.lengths, dtype=np.int32))
        rec.send_columns(entity, indexes=indexes, columns=columns)
        self.time_ns, self.steps, self.lengths, self.components, self.nbytes = [], [], [], {}, 0


def _time_ns(sim_time: float) -> int:
    """Simulated time (s) as integer nanoseconds, the resolution of Rerun's duration timeline."""
    return int(round(float(sim_time) * 1e9))


class PourRecorder:
    """Writes one pour to a ``.rrd`` file.

    path: where the finished recording goes (its folder must exist; an existing file there is replaced at close).
    model: the MuJoCo model whose visible geoms are drawn (groups 0-2, see :mod:`cosim.io.rerun_geometry`).
    config: :class:`RecordingConfig`.
    particle_radius: :data:`PARTICLE_RADIUS`.
    application_id: Rerun application id (the viewer groups recordings by it).
    name: the recording's name in the viewer (e.g. the run's name); None leaves it unnamed.
    properties: shown with the recording (``rr.send_property``): name -> text or number (e.g. the scene's TOML).
    frames: names of MuJoCo sites drawn as tool frames (axes, ``world/frames/<site>``) with the body poses.
    camera: the 3-D view's eye and look target (:class:`cosim.io.rerun_blueprint.Camera`); None: Rerun's default.
        The attribute ``camera`` may be set until :meth:`close`, which writes it into the blueprint.
    liquid_note: a sentence on how the liquid is drawn, added to the colour scale's text (e.g. that a 2-D liquid
        is the pour-plane slice).
    """

    def __init__(
        self,
        path: str | os.PathLike,
        model: mujoco.MjModel,
        config: RecordingConfig = RecordingConfig(),
        *,
        particle_radius: float = 0.0025,
        application_id: str = "cosim",
        name: str | None = None,
        properties: Mapping[str, str | float] | None = None,
        frames: Sequence[str] = (),
        camera: Camera | None = None,
        liquid_note: str = "",
    ) -> None:
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise InputError(f"recording path {self.path}: folder {self.path.parent} does not exist")
        self.config = config
        self.particle_radius = PARTICLE_RADIUS.check("recording.particle_radius", particle_radius)
        self.camera = camera
        self.liquid_note = liquid_note
        self._tmp = self.path.with_name(f".{self.path.name}.{uuid.uuid4().hex}.part")
        self._rec = rr.RecordingStream(application_id)
        self._rec.set_log_time_enabled(False)  # only sim_time and step: the recording is a function of the run
        self._rec.set_log_tick_enabled(False)
        self._rec.save(self._tmp)
        self._open = True
        try:
            if name:
                self._rec.send_recording_name(name)
            if properties:
                self._rec.send_property("run", rr.AnyValues(**dict(properties)))
            visuals, self.skipped_geoms = geom_visuals(model)
            log_static_geometry(self._rec, visuals)
            self._sites = np.array([model.site(s).id for s in frames], dtype=np.int64)
            self._site_paths = [rerun_paths.under(rerun_paths.FRAMES, s) for s in frames]
            self._rec.log(rerun_paths.LIQUID, rr.Points3D.from_fields(radii=[self.particle_radius]), static=True)
            for path in self._site_paths:
                self._rec.log(path, rr.TransformAxes3D(FRAME_AXIS_LENGTH), static=True)
        except BaseException:
            self.abort()
            raise
        # Bodies that carry drawn geometry move; the world body (0) is the world frame itself.
        moving = sorted({v.body_id for v in visuals if v.body_id != 0})
        self._bodies = np.array(moving, dtype=np.int64)
        paths = body_paths(model, moving)
        self._body_paths = [paths[b] for b in moving]
        self._columns: dict[str, _Columns] = {}
        self._signals: list[str] = []
        self._series: dict[str, tuple[str, ...]] = {}
        self._last_slot: int | None = None
        self._cmap = colormaps[SPEED_COLORMAP]
        self._series_colors = colormaps[SERIES_COLORMAP]

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
        """Log body poses, tool frames and liquid particles, at most once per 1/particle_rate_hz of simulated time.

        sim_time: s. step: simulation step index. data: MjData after mj_forward/mj_step (``xpos`` m and ``xquat``
        [w, x, y, z], body -> world; ``site_xpos``, ``site_xmat``). particles: (N, 3) m, world frame. speeds: (N,)
        m/s (colour; None: the colour map's bottom colour). active: (N,) bool, False for particles that left the
        simulation (not drawn). Decimation picks every particle_stride-th particle index before the active mask.
        force: log even if this rate slot was already logged (e.g. the final state).
        Returns whether it logged.
        """
        self._check_open()
        if not (force or self.state_due(sim_time)):
            return False
        slot = self._slot(sim_time)
        self._last_slot = slot if self._last_slot is None else max(slot, self._last_slot)
        t_ns, step = _time_ns(sim_time), int(step)
        quats = xyzw_from_wxyz(data.xquat[self._bodies])
        for k, path in enumerate(self._body_paths):
            self._append(path, rr.Transform3D, t_ns, step, translation=data.xpos[self._bodies[k]][None], quaternion=quats[k][None])
        for k, path in enumerate(self._site_paths):
            quat = np.empty(4)
            mujoco.mju_mat2Quat(quat, data.site_xmat[self._sites[k]])
            self._append(path, rr.Transform3D, t_ns, step, translation=data.site_xpos[self._sites[k]][None], quaternion=xyzw_from_wxyz(quat)[None])
        if particles is not None:
            self._log_particles(t_ns, step, particles, speeds, active)
        return True

    def log_scalars(self, sim_time: float, step: int, values: Mapping[str, float | Mapping[str, float]]) -> None:
        """Log scalar signals at ``signals/<name>`` (every call; buffered).

        values: name -> value, or name -> {series: value} for several series in one plot (their names fixed by the
        first call: a later call with other series names is a ValueError). ``/`` in a name groups signals, and a
        name ends in its unit (``pour_arm/joint_angle_deg``): see :mod:`cosim.io.rerun_blueprint` for the panels.
        """
        self._check_open()
        t_ns, step = _time_ns(sim_time), int(step)
        for name, value in values.items():
            series = tuple(value) if isinstance(value, Mapping) else (rerun_paths.name_parts(name)[-1],)
            known = self._series.get(name)
            if known is None:
                self._series[name] = known = series
                self._signals.append(name)
                colors = self._series_colors(np.arange(len(series)) % self._series_colors.N, bytes=True)  # integers index
                self._rec.log(rerun_paths.signal_path(name), rr.SeriesLines(names=list(series), colors=colors), static=True)
            elif known != series:
                raise ValueError(f"signal {name!r}: series {series} differ from the first call's {known}")
            row = [float(value[k]) for k in series] if isinstance(value, Mapping) else [float(value)]
            self._append(rerun_paths.signal_path(name), rr.Scalars, t_ns, step, scalars=np.array(row))

    def log_arrows(self, sim_time: float, step: int, name: str, origins: np.ndarray, vectors: np.ndarray,
                   labels: Sequence[str] | None = None, color: Sequence[int] = (230, 80, 40, 255)) -> None:
        """Log arrows (origins and vectors (k, 3), m, world frame) at ``world/<name>``; labels: k texts or None."""
        self._check_open()
        batches = dict(origins=np.asarray(origins, dtype=np.float32).reshape(-1, 3),
                       vectors=np.asarray(vectors, dtype=np.float32).reshape(-1, 3))
        batches["colors"] = np.tile(np.asarray(color, dtype=np.uint8), (len(batches["origins"]), 1))
        if labels is not None:
            batches["labels"] = list(labels)
        self._append(rerun_paths.under(rerun_paths.WORLD, name), rr.Arrows3D, _time_ns(sim_time), int(step), **batches)

    def log_points(self, sim_time: float, step: int, name: str, positions: np.ndarray, radius: float,
                   color: Sequence[int], label: str) -> None:
        """Log points ((k, 3) m, world frame; k may be 0: none at this time) at ``world/<name>``, each labelled."""
        self._check_open()
        positions = np.asarray(positions, dtype=np.float32).reshape(-1, 3)
        k = len(positions)
        self._append(
            rerun_paths.under(rerun_paths.WORLD, name), rr.Points3D, _time_ns(sim_time), int(step), positions=positions,
            radii=np.full(k, radius, dtype=np.float32), colors=np.tile(np.asarray(color, dtype=np.uint8), (k, 1)),
            labels=[label] * k,
        )

    def log_path(self, name: str, points: np.ndarray, color: Sequence[int], radius: float, label: str) -> None:
        """Log a static line through ``points`` ((k, 3) m, world frame) at ``world/<name>``, e.g. a whole pour's
        commanded path."""
        self._check_open()
        self._rec.log(
            rerun_paths.under(rerun_paths.WORLD, name),
            rr.LineStrips3D([np.asarray(points, dtype=np.float32)], radii=radius, colors=[color], labels=[label]),
            static=True,
        )

    def log_text(self, sim_time: float, step: int, text: str, level: str = "INFO") -> None:
        """Log a line of the controller's log (``events/phase``): phase changes, and its state while it pours."""
        self._check_open()
        self._append(rerun_paths.PHASE, rr.TextLog, _time_ns(sim_time), int(step), text=[text], level=[level])

    def log_phase(self, sim_time: float, step: int, phase: str, reason: str = "") -> None:
        """Log a controller phase change as the line ``<phase>: <reason>``."""
        self.log_text(sim_time, step, f"{phase}: {reason}" if reason else str(phase))

    # ---- finishing -----------------------------------------------------------------------------------------
    def close(self) -> Path:
        """Send what is buffered and the default blueprint, close the file and move it onto ``path``. Idempotent."""
        if not self._open:
            return self.path
        try:
            for entity, columns in self._columns.items():
                columns.send(self._rec, entity)
            legend = colour_scale_text(SPEED_COLORMAP, self.config.speed_color_max, self.liquid_note)
            self._rec.log(rerun_paths.LEGEND, rr.TextDocument(legend, media_type=rr.MediaType.MARKDOWN), static=True)
            self._rec.send_blueprint(build_blueprint(self._signals, self.camera, {n: len(s) for n, s in self._series.items()}))
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

    def _append(self, entity: str, archetype, t_ns: int, step: int, **batches) -> None:
        columns = self._columns.get(entity)
        if columns is None:
            self._columns[entity] = columns = _Columns(archetype)
        columns.append(t_ns, step, **batches)
        if columns.nbytes >= FLUSH_BYTES:
            columns.send(self._rec, entity)

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
        self._append(
            rerun_paths.LIQUID, rr.Points3D, t_ns, step, positions=positions[index].astype(np.float32), colors=colors,
        )
