"""``cosim pour``: run one pour scene and write its outputs.

Outputs, in a new run folder (``recordings/<UTC time>-<scene name>/``, never an earlier run's) or ``--out DIR``:
``pour.rrd`` (Rerun recording, unless logging is off), ``trajectory.csv``, ``trajectory.json`` and ``trajectory.mcap``
(the arms' checked jerk-limited joint trajectories, the MCAP as ROS 2 ``JointTrajectory`` messages,
:mod:`cosim.trajectory.mcap_file`; the torques their inverse dynamics needs with the liquid's measured wrench are
checked against the joints' rated torques too), ``series.csv`` (per-control-step signals,
:mod:`cosim.io.pour_series`), ``summary.json`` (volumes, the volume left in the pourer and a partial pour's error
first, phases, timings, the arms' load: vessel deviation caused by the liquid, peak servo and required torques against
the rated ones; the trajectory's smoothness per joint, :mod:`cosim.trajectory.smoothness`; versions, the scene). Everything is
written into a hidden temporary folder next to the destination and renamed into place only when the run
succeeded, so a failed or interrupted run leaves no half-written folder behind.
"""

from __future__ import annotations

import json
import os
import platform
import shutil
import sys
import tempfile
from dataclasses import asdict, replace
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path
from typing import Callable

import numpy as np

from controllers.config import CFS_MAX_HEAD, CatcherConfig, PourConfig
from controllers.geometry import VesselGeometry
from controllers.slosh import SloshModel
from cosim.atomic_files import PARTIAL_NAME_EXTRA, PARTIAL_TAG, check_output_folder
from cosim.coupling.exchange import ROLES
from cosim.coupling.follower_lag import follower_lag
from cosim.coupling.loop import CoupledPour, build_pour
from cosim.errors import InputError
from cosim.fluid.config import FluidConfig
from cosim.fluid.runtime import kernel_modules, load_kernels, resolve_device
from cosim.io.pour_series import write_series_csv
from cosim.pour_checks import PourPlan, check_pour
from cosim.pour_scene import PourScene
from cosim.reproducibility import blas_description
from cosim.trajectory.checks import check_torques
from cosim.trajectory.driver_names import driver_joint_names
from cosim.trajectory.export import write_trajectory_files
from cosim.trajectory.smoothness import trajectory_smoothness
from cosim.trajectory.torques import required_torques
from cosim.vessel import VesselSpec

DEFAULT_RECORDINGS = Path("recordings")
VERSIONED_PACKAGES = ("cosim", "warp-lang", "mujoco", "numpy", "control", "ruckig", "rerun-sdk")
# Shown before the pour's warp kernels load: warp compiles them on a machine's first run (every kernel module at
# once, 2-D and 3-D alike: the dimension is a run-time parameter) and reads them from its kernel cache afterwards.
KERNELS_NOTICE = ("loading the liquid's kernels: compiled on the first run on this machine (about a minute, longer on "
                  "a busy CPU), from warp's kernel cache in seconds afterwards ...")


def cfs_head_reference(scene: PourScene, spacing: float) -> float:
    """m, the liquid height over the crest CFS holds: the scene's ``cfs.h_q_ref``, at least
    ``controller.stream_particles`` particle spacings (``spacing``, m) so that the stream is resolved, but at most
    ``CFS_MAX_HEAD`` (0.05 m; 2.1 spacings at the coarsest resolution, 8 across)."""
    floor = scene.controller.stream_particles_in(scene.fluid.dim) * spacing
    return max(scene.controller.cfs.h_q_ref, min(floor, CFS_MAX_HEAD))


# Identifies the slosh plant of a pourer with no closed form: (pourer, fill depth m, the liquid's settings) -> plant.
PlantIdentifier = Callable[[VesselSpec, float, FluidConfig], SloshModel]


def _controller_config(scene: PourScene, spacing: float, slosh: SloshModel | None = None):
    """``pour_config`` callback of :func:`build_pour`: the scene's controller settings on the simulated geometry
    (``slosh``: the pourer's identified plant, None for potential flow), with the lag of the coupling's arm behind its
    tilt command (:func:`cosim.coupling.follower_lag.follower_lag`) for the partial pour's stop."""
    c = scene.controller
    h_q_ref = cfs_head_reference(scene, spacing)

    def make(geometry: VesselGeometry, catcher: CatcherConfig, fill: float, volume: float) -> PourConfig:
        catcher = replace(
            catcher, travel_min=-c.catcher.travel, travel_max=c.catcher.travel, max_speed=c.catcher.max_speed,
            max_accel=c.catcher.max_accel, discharge_coefficient=c.catcher.discharge_coefficient,
            filter_time=c.catcher.filter_time,
        )
        target = scene.liquid.pour_fraction * volume if scene.liquid.pour_fraction < 1.0 else None
        return PourConfig(
            catcher=catcher, vessel=geometry, fill_depth=fill, target_volume=target, control_rate=c.control_rate,
            start_time=scene.coupling.start_delay, sim=c.sim, approach=c.approach, cfs=replace(c.cfs, h_q_ref=h_q_ref),
            returning=c.returning, slosh=slosh, follower_lag=follower_lag(1.0 / c.control_rate),
        )

    return make


def prepare(scene: PourScene, plan: PourPlan | None = None, identify_plant: PlantIdentifier | None = None) -> CoupledPour:
    """Build the pour (robots, liquid, controller, trajectory generators) for ``scene`` from its checked ``plan``
    (:func:`cosim.pour_checks.check_pour`, run here when not given, any estimated run time accepted). A pourer whose
    slosh has no closed form (:meth:`cosim.vessel.VesselSpec.has_closed_form`) takes its plant from
    ``identify_plant``; without one, the controller uses potential flow for the box of its equivalent sizes."""
    plan = plan or check_pour(scene, long_run_ok=True)
    pourer = plan.robots.arms[ROLES[0]].vessel
    slosh = None
    if identify_plant is not None and not pourer.has_closed_form(plan.fluid_base.dim):
        slosh = identify_plant(pourer, scene.liquid.fill_depth, plan.fluid_base)
    return build_pour(
        plan.robots, plan.fluid_base, _controller_config(scene, plan.fluid_base.spacing, slosh), plan.limits, scene.liquid.fill_depth,
        scene.coupling, scene.device, scene.controller.pose_filter, scene.trajectory.sample_rate_hz,
    )


def _new_run_folder(root: Path, name: str) -> Path:
    stamp = datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S")
    candidate = root / f"{stamp}-{name}"
    k = 1
    while candidate.exists():
        k += 1
        candidate = root / f"{stamp}-{name}-{k}"
    return candidate


def _publish(work: Path, final: Path, default_name: str | None) -> Path:
    """Rename the finished run folder ``work`` to ``final`` (replacing an empty --out folder) and return where it
    went. A default run folder (``default_name``: the scene's name) that another run took while this one ran (two
    pours started in the same second pick the same name) is not an error: the run gets the next free name."""
    if final.is_dir() and not any(final.iterdir()):
        final.rmdir()
    try:
        os.replace(work, final)
    except OSError:
        if default_name is None or not final.exists():
            raise
        final = _new_run_folder(final.parent, default_name)
        os.replace(work, final)
    return final


def destination(out: Path | None, name: str) -> Path:
    """The run folder to create: ``out`` (must not exist or be empty) or a new one under recordings/."""
    if out is None:
        return _new_run_folder(DEFAULT_RECORDINGS, name)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise InputError(f"--out: {out} already exists and is not an empty folder (runs never overwrite each other)")
    return out


def package_versions() -> dict[str, str]:
    """Python's version, each of :data:`VERSIONED_PACKAGES`' installed version ('not installed' where absent) and
    numpy's BLAS (:func:`cosim.reproducibility.blas_description`)."""
    out = {"python": platform.python_version()}
    for name in VERSIONED_PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    out["blas"] = blas_description()  # its version and kernels change a pour's bits (cosim.reproducibility)
    return out


def _add_torque_report(arm_load: dict, joint_names, torques: np.ndarray, limits) -> None:
    """Per arm of ``arm_load`` (the pour summary's), each joint's peak required torque (N m) and rated torque."""
    rated = {j.name: j.rated_torque for arm in limits for j in arm.joints}
    peaks = dict(zip(joint_names, np.abs(torques).max(axis=0).tolist()))
    for arm, record in arm_load.items():
        names = [n for n in joint_names if n.startswith(f"{arm}/")]
        record["peak_required_torque"] = {n: peaks[n] for n in names}
        record["rated_torque"] = {n: rated[n] for n in names}


def run_pour(scene: PourScene, out: Path | None = None, progress: bool = True, long_run_ok: bool = False,
             identify_plant: PlantIdentifier | None = None) -> tuple[Path, dict]:
    """Run ``scene`` and write its outputs; returns (run folder, summary). The scene's checks
    (:func:`cosim.pour_checks.check_pour`; ``long_run_ok`` accepts a run estimated at over an hour) come first, and
    with ``progress``, their particle counts and run-time estimate are printed before the first step.
    ``identify_plant``: see :func:`prepare`."""
    field = "--out" if out is not None else "--out (default recordings/)"
    if out is not None:  # before destination() looks it up: a name too long is refused, not an OSError
        check_output_folder(out, field, PARTIAL_NAME_EXTRA)
    final = destination(out, scene.run_name)
    if out is None:  # the new folder under recordings/
        check_output_folder(final, field, PARTIAL_NAME_EXTRA)
    plan = check_pour(scene, long_run_ok)
    if progress:
        print(plan.summary(), file=sys.stderr, flush=True)
        print(KERNELS_NOTICE, file=sys.stderr, flush=True)
    seconds = load_kernels(resolve_device(scene.device), kernel_modules("cosim"))
    if progress:
        print(f"kernels ready in {seconds:.1f} s", file=sys.stderr, flush=True)
    pour = prepare(scene, plan, identify_plant)
    try:
        final.parent.mkdir(parents=True, exist_ok=True)
        work = Path(tempfile.mkdtemp(prefix=f".{final.name}{PARTIAL_TAG}", dir=final.parent))
    except OSError as exc:
        raise InputError(f"{field}: cannot create a folder in {final.parent} ({exc.strerror or exc})") from None
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(work, 0o777 & ~umask)  # mkdtemp makes it private; the run folder gets the usual permissions
    recorder = None
    try:
        # imported here: prepare() needs neither rerun-sdk nor tqdm, and a pour without its recording needs no
        # rerun-sdk (a headless machine may not have it installed)
        from tqdm import tqdm

        callbacks = []
        if scene.logging.enabled:
            from cosim.pour_recording import PourRecordingFeed, open_recorder
            from cosim.pour_scene import dump_scene

            recorder = open_recorder(pour, work / "pour.rrd", scene.logging.recording, scene.run_name, dump_scene(scene))
            feed = PourRecordingFeed(pour, recorder)
            callbacks.append(feed)
        bar = tqdm(total=round(scene.coupling.max_duration, 3), unit="s sim", disable=not progress, mininterval=1.0,
                   bar_format="{desc}{n:.2f} s simulated (at most {total:.1f}) [{elapsed}{postfix}]")
        shown = [0.0]

        def on_step(p: CoupledPour) -> None:
            for cb in callbacks:
                cb(p)
            if progress and p.time - shown[0] >= 0.1:
                bar.update(p.time - shown[0])
                shown[0] = p.time
                rtf = p.time / p.wall_time if p.wall_time else 0.0
                bar.set_postfix_str(f"{p.command.phase.value if p.command else 'start'}, RTF {rtf:.3f}", refresh=False)

        summary = pour.run(on_step)
        bar.close()
        if recorder is not None:
            feed.finish()
            recorder.close()
        write_series_csv(pour.log.rows, work / "series.csv")
        trajectory = pour.recorder.trajectory()
        torques = required_torques(pour.scene, trajectory, pour.sample_wrenches(trajectory.time))
        check_torques(trajectory, torques, pour.recorder.limits)
        _add_torque_report(summary["arm_load"], trajectory.joint_names, torques, pour.recorder.limits)
        write_trajectory_files(
            trajectory, pour.recorder.limits, pour.recorder.sample_rate_hz,
            driver_joint_names(pour.scene, scene.trajectory.joint_prefix),
            work / "trajectory.csv", work / "trajectory.json", work / "trajectory.mcap",
        )
        summary.update(
            scene_name=scene.run_name,
            device=str(pour.fluid.device),
            fluid_threads=pour.fluid.lanes.count,
            fluid_substeps_one_thread=pour.fluid.lanes.substeps_one_thread,
            dim=pour.fluid.config.dim,
            particle_spacing=pour.fluid.config.spacing,
            walls=plan.wall_report(),
            cfs_head_reference=pour.controller.config.cfs.h_q_ref,
            trajectory={
                "duration": float(trajectory.time[-1]),
                "samples": int(len(trajectory.time)),
                "sample_rate_hz": pour.recorder.sample_rate_hz,
                "late_targets": {r.value: pour.generators[r].late_targets for r in ROLES},
                "max_target_error_rad": {r.value: pour.generators[r].max_target_error for r in ROLES},
                "clamped_targets": {r.value: pour.generators[r].clamped_targets for r in ROLES},
                "smoothness": trajectory_smoothness(trajectory),
            },
            versions=package_versions(),
            outputs=sorted(p.name for p in work.iterdir()) + ["summary.json"],
            scene=json.loads(json.dumps(asdict(scene), default=lambda o: getattr(o, "value", str(o)))),
        )
        (work / "summary.json").write_text(json.dumps(summary, indent=2, default=float) + "\n")
        final = _publish(work, final, scene.run_name if out is None else None)
        return final, summary
    except BaseException:
        if recorder is not None:
            recorder.abort()
        shutil.rmtree(work, ignore_errors=True)
        raise
