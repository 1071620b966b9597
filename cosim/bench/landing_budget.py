"""Where the landing prediction's error comes from: a pour's stream followed particle by particle.

    python -m cosim.bench.landing_budget record [SCENE.toml] --out RUN [--threads 1] [--duration S]
    python -m cosim.bench.landing_budget RUN [--json]

``record`` runs the pour as ``cosim pour SCENE --no-log`` does (the controller and the liquid unchanged) and writes
``RUN/series.csv`` (the controller's per-step signals, :mod:`cosim.io.pour_series`), ``RUN/landing.json`` (the
landing accuracy of :func:`cosim.coupling.landing.landing_accuracy`) and ``RUN/particles.npz``: every control step,
each particle's world (x, z) and (v_x, v_z) in the pour plane, by its original index (``pid``), so that each
particle can be followed from the lip to the catcher's rim plane.

The analysis pairs each measured landing sample (the rim-plane crossing at t, the median x of the falling particles
within BAND_SPACINGS of the rim's height, :mod:`cosim.coupling.landing`) with the prediction the metric pairs it
with (made at the launch time t_l, t_l + t_fall(t_l) = t) and splits the error e = x_measured(t) - x_predicted(t_l)
into terms that add up to it exactly:

* ``band``: the measured median against the median of where the same particles actually cross the rim plane
  (the band is two spacings thick: a particle in it is not yet, or no longer, at the rim's height).
* ``flight``: those crossings against where a free ballistic flight from each particle's own launch state would
  have put it (gravity only, Camporredondo et al. 2019, Eqs. 6-7; medians over the band's particles). Launch state:
  the particle's position and velocity at the last control step it spent in the probe's launch window (one to
  four spacings past the lip, :class:`controllers.measurement.LiquidMeasurement`); what pressure, viscosity and
  neighbours do to it in the fall lands here.
* ``spread``: the particles' own ballistic landings against the controller's predictions at their launch steps
  (the ballistic landing of the window's mean launch state): how far one particle lands from the mean of the
  stream it left with.
* ``timing``: those predictions against the one the metric pairs the sample with (at the launch time t_l from the
  mean state's fall time): the pairing of a measurement with a prediction.

Reported per term: its median, mean and the median |error| left when the term is removed (the error it costs).
Beside them: the catcher's offset, the measured landing less vessel B's smoothed centre (not a part of the
prediction's error: the metric compares two landing points), and two predictions that are not the controller's
(:func:`reference_predictions`), and how coherent the stream is (:func:`stream_scatter`: the spread of its launch
v_x about the window's mean, its footprint at the rim plane).
"""

from __future__ import annotations

import argparse
import functools
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from cosim.checks import check_positive
from cosim.coupling.landing import BAND_SPACINGS, MIN_FALL_SPEED_FRACTION, landing_pairs, paired_prediction
from cosim.coupling.outflow import RATE_WINDOW
from cosim.errors import InputError
from cosim.fluid.config import FluidConfig
from cosim.io.pour_series import read_series_csv, write_series_csv
from declared_settings.setting import declared

PARTICLES_FILE = "particles.npz"
SERIES_FILE = "series.csv"
LANDING_FILE = "landing.json"
# The probe's launch window (:class:`controllers.measurement.LiquidMeasurement`, v_q), in particle spacings past the
# lip along world x and below the lip along world z; its top is one spacing over the lip plus the head.
WINDOW_NEAR, WINDOW_FAR, WINDOW_BELOW, WINDOW_ABOVE = 1.0, 4.0, 6.0, 1.0
BRINK_DEPTH_RATIO = 0.715  # brink depth / critical depth of a free overfall (Rouse 1936)


def record(scene, out: Path) -> dict:
    """Run ``scene`` (a :class:`cosim.pour_scene.PourScene`) and write ``out``/series.csv, landing.json and
    particles.npz (module docstring). Returns the landing accuracy."""
    from cosim.fluid.runtime import kernel_modules, load_kernels, resolve_device
    from cosim.pour_run import prepare

    load_kernels(resolve_device(scene.device), kernel_modules("cosim"))
    pour = prepare(scene)
    times, states, active = [], [], []

    def sample(p) -> None:
        if p.steps % p.control_every:
            return
        st = p.fluid.state
        order = np.argsort(st.pid.numpy())
        x, v = st.x.numpy()[order], st.v.numpy()[order]
        times.append(p.time)
        states.append(np.stack([x[:, 0], x[:, 2], v[:, 0], v[:, 2]], axis=1).astype(np.float32))
        active.append(st.active.numpy()[order].astype(bool))

    pour.run(sample)
    out.mkdir(parents=True, exist_ok=True)
    write_series_csv(pour.log.rows, out / SERIES_FILE)
    geo = pour.controller.config.vessel
    np.savez_compressed(
        out / PARTICLES_FILE, t=np.array(times), state=np.array(states), active=np.array(active),
        spacing=pour.fluid.config.spacing, gravity=pour.fluid.config.gravity_magnitude,
        inner_width=geo.inner_width, inner_height=geo.inner_height, wall=geo.wall_thickness,
        catcher_home_x=pour.controller.config.catcher.home_x,
    )
    accuracy = pour.landing_accuracy()
    (out / LANDING_FILE).write_text(json.dumps(accuracy, indent=2) + "\n")
    return accuracy



def _tilted(theta: np.ndarray, a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """World (x, z) of the vessel-frame vector (a, b) on a vessel tilted by ``theta`` (rad, about world +y)."""
    return np.cos(theta) * a + np.sin(theta) * b, -np.sin(theta) * a + np.cos(theta) * b


def ballistic_x(x0, z0, vx, vz, rim_z, gravity):
    """World x (m) where a particle launched at (x0, z0) with (vx, vz) crosses z = rim_z under gravity alone."""
    drop = np.maximum(np.asarray(z0) - rim_z, 0.0)
    return x0 + vx * (vz + np.sqrt(vz * vz + 2.0 * gravity * drop)) / gravity


class StreamParticles:
    """A recorded pour (``record``'s folder): per control step of series.csv, the particles in the probe's launch
    window and in the rim band, and each particle's way down through the rim plane."""

    def __init__(self, run: Path):
        self.series = {k: np.asarray(v) for k, v in read_series_csv(run / SERIES_FILE).items()}
        data = np.load(run / PARTICLES_FILE)
        s = self.series
        self.t = s["t"].astype(float)
        period = float(np.median(np.diff(self.t)))
        rows = np.rint(data["t"] / period).astype(int)  # series row of each particle sample
        # a run cut off by its duration samples the particles after its last step, which no series row follows
        logged = rows < len(self.t)
        rows = rows[logged]
        n = data["state"].shape[1]
        self.state = np.full((len(self.t), n, 4), np.nan)
        self.state[rows] = data["state"][logged]
        inactive = np.zeros((len(self.t), n), bool)
        inactive[rows] = ~data["active"][logged]
        self.state[inactive] = np.nan
        self.dx, self.gravity = float(data["spacing"]), float(data["gravity"])
        self.home_x = float(data["catcher_home_x"])
        x, z = self.state[..., 0], self.state[..., 1]
        lip_x, lip_z, rim = s["lip_x"][:, None], s["lip_z"][:, None], s["catcher_rim_z"][:, None]
        # outside the pourer's inner box (vessel frame x in [-B/2, B/2], z in [0, L]), as the probe requires
        half, height, wall = 0.5 * float(data["inner_width"]), float(data["inner_height"]), float(data["wall"])
        theta = s["tilt"][:, None]
        ox, oz = _tilted(theta, half + wall, height)
        rx, rz = x - (lip_x - ox), z - (lip_z - oz)
        local_x, local_z = _tilted(-theta, rx, rz)
        inside = (np.abs(local_x) <= half) & (local_z >= 0.0) & (local_z <= height)
        top = lip_z + self.dx * WINDOW_ABOVE + np.maximum(s["h_q"], 0.0)[:, None]
        self.in_window = ((x >= lip_x + WINDOW_NEAR * self.dx) & (x <= lip_x + WINDOW_FAR * self.dx)
                          & (z >= lip_z - WINDOW_BELOW * self.dx) & (z <= top) & ~inside)
        min_speed = MIN_FALL_SPEED_FRACTION * np.sqrt(2.0 * self.gravity * np.maximum(s["lip_z"] - s["catcher_rim_z"], 0.0))
        self.in_band = (np.abs(z - rim) <= BAND_SPACINGS * self.dx) & (self.state[..., 3] < -min_speed[:, None])

    @functools.cached_property
    def crossings(self) -> tuple[np.ndarray, np.ndarray]:
        """:func:`all_crossings` of this run, found once for every statistic that reads them."""
        return all_crossings(self)

    def launch_step(self, i: int, k: int) -> int | None:
        """The last step at or before ``k`` at which particle ``i`` was in the launch window (None: never)."""
        steps = np.flatnonzero(self.in_window[: k + 1, i])
        return int(steps[-1]) if len(steps) else None

    def crossing_x(self, i: int, after: int) -> float:
        """World x (m) where particle ``i`` first moves down through the rim plane after step ``after``
        (interpolated linearly between the two control steps around it); NaN when it does not."""
        z = self.state[after:, i, 1] - self.series["catcher_rim_z"][after:]
        down = np.flatnonzero((z[:-1] >= 0.0) & (z[1:] < 0.0))
        if not len(down):
            return math.nan
        j = after + int(down[0])
        f = z[j - after] / (z[j - after] - z[j + 1 - after])
        return float((1.0 - f) * self.state[j, i, 0] + f * self.state[j + 1, i, 0])


TERMS = ("band", "flight", "spread", "timing")


def decompose(run: Path) -> dict:
    """The landing error's terms (module docstring) over the measured samples of a recorded pour."""
    sp = StreamParticles(run)
    s = sp.series
    in_cfs = np.isin(s["phase"], ("cfs", "cfs_final"))
    steps, _ = landing_pairs(sp.t, s["landing_x"], s["landing_fall_time"], s["landing_measured_x"], in_cfs)
    predicted = paired_prediction(sp.t, s["landing_x"], s["landing_fall_time"], in_cfs, sp.t[steps])
    rows, skipped = [], 0
    for k, xp in zip(steps, predicted):
        band = np.flatnonzero(sp.in_band[k])
        launched = [(i, sp.launch_step(i, k)) for i in band]
        launched = [(i, j) for i, j in launched if j is not None]
        crossings = [sp.crossing_x(i, j) for i, j in launched]
        if not launched or not np.all(np.isfinite(crossings)):
            skipped += 1
            continue
        x0, z0, vx, vz = (np.array([sp.state[j, i, c] for i, j in launched]) for c in range(4))
        ballistic = ballistic_x(x0, z0, vx, vz, s["catcher_rim_z"][k], sp.gravity)
        at_launch = np.array([s["landing_x"][j] for _, j in launched])
        measured = float(s["landing_measured_x"][k])
        x_c, x_b, x_l = float(np.median(crossings)), float(np.median(ballistic)), float(np.median(at_launch))
        rows.append({
            "t": float(sp.t[k]), "error": measured - xp, "band": measured - x_c, "flight": x_c - x_b,
            "spread": x_b - x_l, "timing": x_l - xp, "particles": len(band),
            "catcher_offset": measured - (sp.home_x + float(s["smoothed_catcher_dx"][k])),
        })
    return {"samples": len(steps), "decomposed": len(rows), "skipped": skipped, "rows": rows,
            "references": reference_predictions(sp, steps, predicted), "scatter": stream_scatter(sp)}


def all_crossings(sp: StreamParticles) -> tuple[np.ndarray, np.ndarray]:
    """Time (s) and world x (m) of every particle's first downward crossing of the rim plane faster than the band's
    minimum speed, in time order (interpolated linearly between control steps)."""
    rim = sp.series["catcher_rim_z"][:, None]
    z = sp.state[..., 1] - rim
    speed = MIN_FALL_SPEED_FRACTION * np.sqrt(2.0 * sp.gravity * np.maximum(sp.series["lip_z"] - sp.series["catcher_rim_z"], 0.0))
    down = (z[:-1] >= 0.0) & (z[1:] < 0.0) & (sp.state[1:, :, 3] < -speed[1:, None])
    times, xs = [], []
    for i in np.flatnonzero(down.any(axis=0)):
        j = int(np.flatnonzero(down[:, i])[0])
        f = z[j, i] / (z[j, i] - z[j + 1, i])
        times.append(sp.t[j] + f * (sp.t[j + 1] - sp.t[j]))
        xs.append((1.0 - f) * sp.state[j, i, 0] + f * sp.state[j + 1, i, 0])
    order = np.argsort(times)
    return np.asarray(times)[order], np.asarray(xs)[order]


def reference_predictions(sp: StreamParticles, steps: np.ndarray, predicted: np.ndarray) -> dict:
    """Median |error| (mm) over the measured samples of two predictions that are not the controller's:

    ``stream_centre``: the mean crossing x of all other particles that cross the rim plane within RATE_WINDOW / 2 of
    the sample (what a prediction that knew the stream's centre exactly would score: the floor a single-particle
    sample leaves to any prediction of the stream); ``crest_head``: the landing of a jet launched horizontally at the
    lip with the brink velocity of critical flow over the crest, v_b = sqrt(g y_c) / 0.715, y_c = 2 h_q / 3
    (critical depth over a broad crest; brink depth 0.715 y_c, Rouse 1936), falling freely, at the launch time the
    metric pairs (what the head over the crest alone predicts). Also the stream's launch point, the window's mean
    position past the lip (median over the flowing steps, mm)."""
    s = sp.series
    measured = s["landing_measured_x"][steps]
    times, xs = sp.crossings
    centre = []
    for k in steps:
        near = (np.abs(times - sp.t[k]) <= 0.5 * RATE_WINDOW) & (np.abs(times - sp.t[k]) > 0.5 * (sp.t[1] - sp.t[0]))
        centre.append(xs[near].mean() if near.any() else math.nan)
    head = np.maximum(s["h_q"], 0.0)
    v_brink = np.sqrt(sp.gravity * 2.0 * head / 3.0) / BRINK_DEPTH_RATIO
    drop = np.maximum(s["lip_z"] - s["catcher_rim_z"], 0.0)
    fall = np.sqrt(2.0 * drop / sp.gravity)
    launch = sp.t[steps] - np.interp(sp.t[steps], sp.t + fall, fall)
    crest_head = np.interp(launch, sp.t, s["lip_x"] + v_brink * fall)
    flowing = np.isfinite(s["landing_fall_time"]) & np.isin(s["phase"], ("cfs", "cfs_final"))
    return {
        "stream_centre_median_abs_mm": 1e3 * float(np.nanmedian(np.abs(measured - np.asarray(centre)))),
        "crest_head_median_abs_mm": 1e3 * float(np.median(np.abs(measured - crest_head))),
        "crest_head_mean_mm": 1e3 * float(np.mean(measured - crest_head)),
        "controller_median_abs_mm": 1e3 * float(np.median(np.abs(measured - predicted))),
        "launch_point_past_lip_mm": [1e3 * float(np.median(s[c][flowing])) for c in ("jet_dx", "jet_dz")],
        "crossings": len(times),
    }


def stream_scatter(sp: StreamParticles) -> dict:
    """How coherent the stream is where the controller measures it and where it lands, over CFS (the flowing
    steps, as the budget's samples):

    ``launch_vx_rms_mm_s``: the root mean square over every particle in the probe's launch window at every control
    step holding two or more of its v_x's deviation from that step's window mean (mm/s): the velocity noise the
    controller's mean launch state averages over and a single particle lands with (a particle's landing moves by its
    v_x deviation times the fall time; v_z is left out, as it varies across the window's height by gravity alone);
    ``window_particles``: the median count in the window at those steps; ``footprint_median_abs_mm``: the median over every rim-plane
    crossing of |x - the mean x of the other crossings within RATE_WINDOW / 2| (mm), the stream's half width where
    it lands, the single-sample floor that ``stream_centre`` scores on the samples alone."""
    s = sp.series
    flowing = np.isfinite(s["landing_fall_time"]) & np.isin(s["phase"], ("cfs", "cfs_final"))
    deviations, counts = [], []
    for k in np.flatnonzero(flowing):
        vx = sp.state[k, sp.in_window[k], 2]
        if len(vx) >= 2:
            deviations.append(vx - vx.mean())
            counts.append(len(vx))
    rms = math.sqrt(float(np.mean(np.concatenate(deviations) ** 2))) if deviations else math.nan
    times, xs = sp.crossings
    cfs = np.interp(times, sp.t, flowing.astype(float)) > 0.5
    offsets = []
    for i in np.flatnonzero(cfs):
        near = np.abs(times - times[i]) <= 0.5 * RATE_WINDOW
        near[i] = False
        if near.any():
            offsets.append(xs[i] - xs[near].mean())
    return {
        "launch_vx_rms_mm_s": 1e3 * rms,
        "window_steps": len(counts),
        "window_particles": float(np.median(counts)) if counts else 0.0,
        "footprint_median_abs_mm": 1e3 * float(np.median(np.abs(offsets))) if offsets else math.nan,
        "footprint_crossings": len(offsets),
    }


def budget(decomposition: dict) -> dict:
    """Per term: median, mean (mm) and the median |error| (mm) left with that term removed; the error's own."""
    rows = decomposition["rows"]
    error = np.array([r["error"] for r in rows])
    out = {"samples": decomposition["samples"], "decomposed": decomposition["decomposed"],
           "median_abs_error_mm": 1e3 * float(np.median(np.abs(error))), "mean_error_mm": 1e3 * float(np.mean(error)),
           "particles_in_band_median": float(np.median([r["particles"] for r in rows]))}
    for term in (*TERMS, "catcher_offset"):
        v = np.array([r[term] for r in rows])
        out[term] = {"median_mm": 1e3 * float(np.median(v)), "mean_mm": 1e3 * float(np.mean(v)),
                     "median_abs_mm": 1e3 * float(np.median(np.abs(v)))}
        if term in TERMS:
            out[term]["without_mm"] = 1e3 * float(np.median(np.abs(error - v)))
    out["references"] = decomposition["references"]
    out["scatter"] = decomposition["scatter"]
    return out


def check_run(run: Path) -> None:
    """A folder ``record`` wrote: its series.csv and particles.npz are there (InputError naming RUN otherwise)."""
    missing = [name for name in (SERIES_FILE, PARTICLES_FILE) if not (run / name).is_file()]
    if missing:
        raise InputError(f"RUN: {run} has no {' or '.join(missing)} (a folder written by "
                         f"'python -m cosim.bench.landing_budget record ... --out RUN')")


def report(b: dict) -> str:
    """The budget as text: the error, each term's share, the catcher and the reference predictions (mm)."""
    r = b["references"]
    lines = [f"{b['decomposed']} of {b['samples']} samples, median {b['median_abs_error_mm']:.2f} mm, mean "
             f"{b['mean_error_mm']:+.2f} mm; particles in the band per sample: median {b['particles_in_band_median']:.0f}",
             f"{'term':<8} {'median |term|':>14} {'mean':>8} {'median |error| without it':>27}"]
    for term in TERMS:
        t = b[term]
        lines.append(f"{term:<8} {t['median_abs_mm']:>14.2f} {t['mean_mm']:>+8.2f} {t['without_mm']:>27.2f}")
    c = b["catcher_offset"]
    lines += [f"catcher's centre to the measured landing: median {c['median_mm']:+.2f} mm, median |offset| {c['median_abs_mm']:.2f} mm",
              f"stream's centre known exactly: {r['stream_centre_median_abs_mm']:.2f} mm; launched from the crest and head: "
              f"{r['crest_head_median_abs_mm']:.2f} mm (mean {r['crest_head_mean_mm']:+.2f} mm); launch point "
              f"{r['launch_point_past_lip_mm'][0]:.1f} mm past the lip, {r['launch_point_past_lip_mm'][1]:+.1f} mm above it"]
    sc = b["scatter"]
    lines.append(f"the stream's scatter: launch v_x about the window's mean, rms {sc['launch_vx_rms_mm_s']:.1f} mm/s "
                 f"({sc['window_steps']} steps, median "
                 f"{sc['window_particles']:.0f} particles in the window); footprint at the rim plane, median "
                 f"|x - centre| {sc['footprint_median_abs_mm']:.2f} mm ({sc['footprint_crossings']} crossings)")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        if argv[:1] == ["record"]:
            return _record_command(argv[1:])
        p = argparse.ArgumentParser(prog="python -m cosim.bench.landing_budget", description=__doc__,
                                    formatter_class=argparse.RawDescriptionHelpFormatter)
        p.add_argument("run", type=Path, help="a folder written by 'record'")
        p.add_argument("--json", action="store_true", help="print the budget as JSON")
        args = p.parse_args(argv)
        check_run(args.run)
        b = budget(decompose(args.run))
    except InputError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(json.dumps(b, indent=2) if args.json else report(b))
    return 0


def _record_command(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="python -m cosim.bench.landing_budget record", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", nargs="?", type=Path, help="scene TOML file (default: the embedded default scene)")
    p.add_argument("--out", type=Path, required=True, help="new folder for series.csv, landing.json, particles.npz")
    p.add_argument("--threads", type=int, help="CPU threads of the liquid solver (overrides fluid.cpu_threads)")
    p.add_argument("--duration", type=float, help="longest simulated time, s (overrides coupling.max_duration)")
    args = p.parse_args(argv)
    threads = declared(FluidConfig, "cpu_threads").check("--threads", args.threads) if args.threads is not None else None
    duration = check_positive("--duration", args.duration, "s", 600.0) if args.duration is not None else None
    if args.out.exists() and (not args.out.is_dir() or any(args.out.iterdir())):
        raise InputError(f"--out: {args.out} already exists and is not an empty folder")
    from cosim.pour_scene import PourScene, load_scene

    scene = load_scene(args.scene).named_after(args.scene) if args.scene is not None else PourScene()
    if threads is not None:
        scene = replace(scene, fluid=replace(scene.fluid, cpu_threads=threads))
    if duration is not None:
        scene = replace(scene, coupling=replace(scene.coupling, max_duration=duration))
    scene = replace(scene, logging=replace(scene.logging, enabled=False))
    print(json.dumps(record(scene, args.out)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
