"""What the pour controller reads from the SPH liquid each control step (``controllers.LiquidMeasurement``).

Implements the measurement contract written in :class:`controllers.measurement.LiquidMeasurement` exactly
(free-surface angle theta1 from a least-squares line through the liquid's column heights in the pourer's frame,
:mod:`cosim.coupling.free_surface`; h_q from the liquid's volume over the crest, :mod:`cosim.coupling.crest_head`; v_q through the
lip plane; volumes; lip and catcher-rim positions). The pour lip used here is where the simulated liquid leaves the
vessel: the outer top edge of the wall as the liquid sees it (``FluidModel.wall_thickness``, at least the
dummy-particle layers), which is also the wall thickness given to the controller, so that its jet launch point is
the simulated one.

Computed on the fluid's device, from its particle arrays as they are (any order): warp kernels reduce the
particles to fixed-order chunk sums of the column heights, of the liquid over the crest and of the stream leaving the
lip and the few particles crossing vessel B's rim plane; the host reads back only those, so its work per control
step does not grow with the particle count. Every reduction is order-independent (a median of a set) or summed in
a fixed order (chunks), so the measurement is deterministic on any device.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import warp as wp

from controllers.geometry import height_above
from controllers.measurement import LiquidMeasurement
from cosim.coupling.crest_head import REACH, WINDOW_WIDTH, head_from_volume, head_window, sum_crest_head, volume_over_crest
from cosim.coupling.free_surface import (LAYER_SPACINGS, MIN_FIT_COLUMNS, add_column_chunks, column_count, column_scale, layer_levels,
                                         sum_columns, surface_heights, surface_line)
from cosim.coupling.landing import BAND_SPACINGS, MIN_FALL_SPEED_FRACTION
from cosim.coupling.pourer_frame import PourerFrame, inner_local
from cosim.frames import Pose, tilt_about_y
from cosim.vessel import VesselShape, VesselSpec

CHUNKS = 64  # fixed-order reductions: per-chunk sums, then the chunks in order
STREAM_SUM_COLUMNS = 5  # per chunk: count, sum vx, sum vz, sum x, sum z of the leaving particles


def _read_only(values: np.ndarray) -> np.ndarray:
    values.flags.writeable = False
    return values


@dataclass(frozen=True)
class MeasurementGeometry:
    """What the measurement needs to know: the pourer (spec, wall thickness the liquid sees), the catcher's
    inner height, the smoothing length h and spacing dx (m), and the liquid's initial volume (m^3)."""

    pourer: VesselSpec
    wall_thickness: float
    catcher_height: float
    smoothing_length: float
    spacing: float
    initial_volume: float
    dim: int

    # made once (the probe reads them several times a control period): read-only arrays
    @cached_property
    def crest_local(self) -> np.ndarray:
        return _read_only(np.array([0.5 * self.pourer.inner_width, 0.0, self.pourer.inner_height]))

    @cached_property
    def lip_local(self) -> np.ndarray:
        return _read_only(np.array([0.5 * self.pourer.inner_width + self.wall_thickness, 0.0, self.pourer.inner_height]))

    @cached_property
    def columns(self) -> int:
        """Number of free-surface columns (:func:`cosim.coupling.free_surface.column_count`)."""
        return column_count(self.pourer.inner_width, self.spacing)


@wp.kernel
def sum_leaving_stream(
    # Model
    frames: wp.array(dtype=PourerFrame),
    lip: wp.vec3,
    dx: float,
    top: float,
    n: int,
    chunk: int,
    # State in
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    # Out
    sums: wp.array2d(dtype=float),
):
    """Per chunk of ``chunk`` consecutive particles, in order: count, sum vx, sum vz, sum x, sum z of the particles
    that have just left over the lip (outside the inner box, x in [x_lip + dx, x_lip + 4 dx], z in
    [z_lip - 6 dx, top]); the pourer's frame is ``frames[0]``."""
    k = wp.tid()
    f = frames[0]
    count = float(0.0)
    svx = float(0.0)
    svz = float(0.0)
    sx = float(0.0)
    sz = float(0.0)
    for i in range(k * chunk, wp.min((k + 1) * chunk, n)):
        if active[i] == 0:
            continue
        xi = x[i]
        if xi[0] < lip[0] + dx or xi[0] > lip[0] + 4.0 * dx or xi[2] < lip[2] - 6.0 * dx or xi[2] > top:
            continue
        if inner_local(f, xi)[3] > 0.0:
            continue
        count += 1.0
        svx += v[i][0]
        svz += v[i][2]
        sx += xi[0]
        sz += xi[2]
    sums[k, 0] = count
    sums[k, 1] = svx
    sums[k, 2] = svz
    sums[k, 3] = sx
    sums[k, 4] = sz


@wp.kernel
def collect_rim_crossing(
    # Model
    rim_z: float,
    band: float,
    min_speed: float,
    # State in
    x: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    active: wp.array(dtype=wp.int32),
    # Out
    count: wp.array(dtype=wp.int32),
    crossing_x: wp.array(dtype=float),
):
    """World x of the particles falling through the rim plane (within ``band`` of it, moving down faster than
    ``min_speed``), appended in any order (only their median is used)."""
    i = wp.tid()
    if active[i] == 0:
        return
    xi = x[i]
    if wp.abs(xi[2] - rim_z) <= band and v[i][2] < -min_speed:
        slot = wp.atomic_add(count, 0, 1)
        crossing_x[slot] = xi[0]


def _packed_scalar(value: object) -> tuple | None:
    """A launch argument that is a plain int or float as (type, its exact value), to compare with the one a recorded
    launch holds (a float by its hex digits, so that 0.0 and -0.0 differ); None for anything else (packed every
    time)."""
    if type(value) is int:
        return (int, value)
    if type(value) is float:
        return (float, value.hex())
    return None


def argument_layout(kernel) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """(the positions of ``kernel``'s array arguments, those of the others), from its signature: what a launch's
    key reads and what it may have to pack again, without looking at each argument's type on every launch."""
    arrays = tuple(k for k, arg in enumerate(kernel.adj.args) if wp.types.is_array(arg.type))
    return arrays, tuple(k for k in range(len(kernel.adj.args)) if k not in arrays)


class LiquidProbe:
    """The controller's measurement of a liquid of ``n_particles`` on ``device`` (scratch arrays allocated once).

    Each call reads the particle arrays it is given (world frame: positions (N,) vec3 m, velocities (N,) vec3
    m/s, active (N,) int32), e.g. the fluid solver's current state."""

    def __init__(self, geo: MeasurementGeometry, n_particles: int, device):
        self.geo = geo
        self.n = n_particles
        self.device = device
        cols = max(geo.columns, 1)
        self._column_sums = wp.zeros((CHUNKS, cols), dtype=float, device=device)
        self._column_heights = wp.zeros(cols, dtype=float, device=device)  # M_k (m)
        self._column_levels = wp.zeros(cols, dtype=float, device=device)  # z_k (m)
        self._column_volumes = wp.zeros(cols, dtype=float, device=device)  # m_k (m)
        self._head_sums = wp.zeros(CHUNKS, dtype=float, device=device)
        self._sums = wp.zeros((CHUNKS, STREAM_SUM_COLUMNS), dtype=float, device=device)
        self._crossing_count = wp.zeros(1, dtype=wp.int32, device=device)
        self._crossing_x = wp.zeros(max(n_particles, 1), dtype=float, device=device)
        # on the CPU, the read-back arrays' numpy views, made once (they share the arrays' memory: each is read
        # before the next launch writes it); on other devices each read is a copy to the host
        results = (self._column_levels, self._column_volumes, self._head_sums, self._sums, self._crossing_count, self._crossing_x)
        self._views = {id(a): a.numpy() for a in results} if wp.get_device(device).is_cpu else None
        self._commands: dict[tuple, tuple[wp.Launch, list]] = {}  # the launch and its scalar arguments as packed
        self._layouts: dict[str, tuple[tuple[int, ...], tuple[int, ...]]] = {}  # each kernel's argument_layout
        spec = geo.pourer
        frame = PourerFrame()  # the fixed fields once; :meth:`_set_pose` writes the pose before each measurement
        frame.half_width = 0.5 * spec.inner_width
        frame.half_depth = 0.5 * spec.section_depth
        frame.height = spec.inner_height
        frame.dim = geo.dim
        frame.round_section = int(geo.dim == 3 and spec.shape is VesselShape.CYLINDER)
        self._frame = wp.array([frame], dtype=PourerFrame, device=device)  # one entry: the kernels read it there
        self._window = wp.zeros(1, dtype=wp.vec3, device=device)  # the crest head's window centre (m)
        # what :meth:`_set_pose` writes: the arrays' own memory on the CPU, host copies uploaded elsewhere
        self._frame_host, self._window_host = self._frame.numpy(), self._window.numpy()
        self._graphs: dict[tuple[int, int], object] = {}  # the surface launches captured, per particle array set

    def _launch(self, kernel, dim: int, inputs: list, outputs: list) -> None:
        """``wp.launch(kernel, dim, inputs, outputs)`` through a recorded launch kept per kernel and array set (the
        solver's particle arrays alternate between two): each call packs only the arguments that are not arrays
        (packing them all was most of the probe's host time), and of those only the ones that changed (a plain
        int or float the launch holds already, to the bit, is not packed again; structs and vectors always are)."""
        layout = self._layouts.get(kernel.key)
        if layout is None:
            layout = self._layouts[kernel.key] = argument_layout(kernel)
        arrays, values = layout
        arguments = (*inputs, *outputs)
        key = (kernel.key, dim, *[arguments[k].ptr for k in arrays])
        entry = self._commands.get(key)
        if entry is None:
            command = wp.launch(kernel, dim=dim, inputs=inputs, outputs=outputs, device=self.device, record_cmd=True)
            self._commands[key] = (command, [_packed_scalar(value) for value in inputs])
        else:
            command, packed = entry
            for k in values:
                value = inputs[k]
                scalar = _packed_scalar(value)
                if scalar is None or scalar != packed[k]:
                    command.set_param_at_index(k, value)
                    packed[k] = scalar
        command.launch()

    def read_back(self, array: wp.array, size: int | None = None) -> np.ndarray:
        """The first ``size`` values (None: all) of one of the probe's result arrays on the host: every value the
        probe reads from the device comes through here. On the CPU the array's numpy view (valid until the next
        launch writes it), elsewhere a copy of just those values."""
        if self._views is None:
            return (array if size is None else array[:size]).numpy()
        return self._views[id(array)][:size]

    def _set_pose(self, pose: Pose, window: np.ndarray) -> None:
        """The pourer's frame at ``pose`` and the crest head's window centre (m) into the arrays the kernels read
        (float32, rounded as a launch's own vectors are)."""
        self._frame_host["origin"][0] = pose.position
        self._frame_host["rotation"][0] = pose.rotation
        self._window_host[0] = window
        if self._views is None:  # not the arrays' own memory: uploaded
            self._frame.assign(self._frame_host)
            self._window.assign(self._window_host)

    def _surface_launches(self, x: wp.array, active: wp.array) -> None:
        """The launches that need nothing from the host but the pose: the free-surface columns' heights, levels and
        volumes over them, and the liquid over the crest (their scalars are the geometry's, fixed)."""
        geo, dx, device = self.geo, self.geo.spacing, self.device
        chunk = max(math.ceil(self.n / CHUNKS), 1)
        if geo.columns:
            scale, sums = column_scale(dx, geo.dim), self._column_sums
            columns = [self._frame, WINDOW_WIDTH * dx, dx, geo.columns, self.n, chunk, x, active, self._column_levels]
            wp.launch(sum_columns, CHUNKS, [*columns, 0], [sums], device=device)
            wp.launch(add_column_chunks, geo.columns, [sums, CHUNKS, scale], [self._column_heights], device=device)
            wp.launch(layer_levels, geo.columns, [self._column_heights, LAYER_SPACINGS * dx, float(REACH) * dx], [self._column_levels], device=device)
            wp.launch(sum_columns, CHUNKS, [*columns, 1], [sums], device=device)
            wp.launch(add_column_chunks, geo.columns, [sums, CHUNKS, scale], [self._column_volumes], device=device)
        wp.launch(sum_crest_head, CHUNKS, [self._window, dx, WINDOW_WIDTH * dx, geo.dim, self.n, chunk, x, active], [self._head_sums], device=device)

    def _measure_surface(self, x: wp.array, active: wp.array) -> None:
        """:meth:`_surface_launches` as one graph, captured at the first call with these particle arrays (the solver's
        alternate between two) and replayed: the launches' argument handling once instead of at every measurement."""
        key = (x.ptr, active.ptr)
        graph = self._graphs.get(key)
        if graph is None:
            with wp.ScopedCapture(device=self.device) as capture:
                self._surface_launches(x, active)
            graph = self._graphs[key] = capture.graph
        wp.capture_launch(graph)

    def measure(
        self, t: float, pourer_pose: Pose, catcher_pose: Pose, x: wp.array, v: wp.array, active: wp.array,
        volume_in_pourer: float,
    ) -> LiquidMeasurement:
        """The measurement at time ``t`` (s) with the vessels at these poses, from the particle arrays and the
        solver's count-based volume in the pourer (m^3)."""
        geo, dx = self.geo, self.geo.spacing
        height = geo.pourer.inner_height
        tilt = tilt_about_y(pourer_pose.rotation)
        crest = pourer_pose.transform(geo.crest_local[None, :])[0]
        chunk = max(math.ceil(self.n / CHUNKS), 1)
        self._set_pose(pourer_pose, head_window(crest, dx))
        self._measure_surface(x, active)
        levels = self.read_back(self._column_levels, geo.columns).astype(np.float64)
        heights = surface_heights(levels, self.read_back(self._column_volumes, geo.columns).astype(np.float64), dx)
        c, slope, columns = surface_line(heights, dx)
        theta1 = math.atan(slope) if columns >= MIN_FIT_COLUMNS else tilt

        volume = volume_over_crest(self.read_back(self._head_sums), dx, geo.dim)
        if volume > 0.0:
            h_q = head_from_volume(volume, dx)
        elif columns >= MIN_FIT_COLUMNS:
            h_q = min(height_above((geo.crest_local[0], geo.crest_local[2]), c, theta1, tilt), 0.0)
        else:
            h_q = -height  # no surface to measure: far below the crest

        lip = pourer_pose.transform(geo.lip_local[None, :])[0]
        top = lip[2] + dx + max(h_q, 0.0)
        self._launch(sum_leaving_stream, CHUNKS, [self._frame, wp.vec3(*lip), dx, top, self.n, chunk, x, v, active], [self._sums])
        count, svx, svz, sx, sz = self.read_back(self._sums).astype(np.float64).sum(axis=0)
        if count > 0:
            v_q, v_q_z = svx / count, svz / count
            jet_dx, jet_dz = sx / count - lip[0], sz / count - lip[2]
        else:
            v_q = v_q_z = jet_dx = jet_dz = 0.0
        rim = catcher_pose.transform(np.array([[0.0, 0.0, geo.catcher_height]]))[0]
        return LiquidMeasurement(
            t=t,
            tilt=tilt,
            theta1=theta1,
            h_q=h_q,
            v_q=float(v_q),
            volume_in_pourer=volume_in_pourer,
            poured_volume=max(geo.initial_volume - volume_in_pourer, 0.0),
            lip_x=float(lip[0]),
            lip_z=float(lip[2]),
            catcher_rim_z=float(rim[2]),
            v_q_z=float(v_q_z),
            jet_dx=float(jet_dx),
            jet_dz=float(jet_dz),
        )

    def stream_crossing_x(self, x: wp.array, v: wp.array, active: wp.array, rim_z: float, lip_z: float, gravity: float) -> float:
        """Median world x (m) of the active particles falling through the plane z = ``rim_z`` (within
        BAND_SPACINGS spacings, faster than MIN_FALL_SPEED_FRACTION of the free fall from ``lip_z``); NaN when
        none is (:mod:`cosim.coupling.landing`)."""
        drop = max(lip_z - rim_z, 0.0)
        min_speed = MIN_FALL_SPEED_FRACTION * math.sqrt(2.0 * gravity * drop)
        if self._views is None:
            self._crossing_count.zero_()
        else:
            self._views[id(self._crossing_count)].fill(0)
        if self.n:
            self._launch(collect_rim_crossing, self.n, [rim_z, BAND_SPACINGS * self.geo.spacing, min_speed, x, v, active], [self._crossing_count, self._crossing_x])
        count = int(self.read_back(self._crossing_count)[0])
        if count == 0:
            return math.nan
        return float(np.median(self.read_back(self._crossing_x, count).astype(np.float64)))
