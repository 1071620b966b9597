"""What a pour puts into its Rerun recording (:class:`cosim.io.recording.PourRecorder`), in units a robotics user
reads: angles in deg, volumes in mL, forces in N, torques in N m, lengths in mm.

Signals (``signals/<name>``, one plot each, :mod:`cosim.io.rerun_blueprint`), every control step:

- ``pour/tilt_deg``: the pourer's commanded tilt (forward kinematics of the arms' commanded joint state), its
  measured tilt and the liquid surface's angle theta1;
- ``pour/head_over_crest_mm`` (h_q), ``pour/outflow_speed_m_s`` (v_q), ``pour/volume_mL`` (in the pourer, in the
  catcher, outside both), ``pour/landing_x_mm`` (predicted and measured world x where the stream crosses the
  catcher's rim height);
- ``pourer|catcher/liquid_force_N`` and ``.../liquid_torque_N_m``: the liquid's wrench on each vessel (world axes,
  about the vessel's centre of mass);
- ``<arm>/joint_angle_deg`` and ``<arm>/joint_speed_deg_s``: each arm's commanded joint state.

In 3-D, with the body poses: each vessel's frame (the arm's tool frame) as axes, the liquid's force on each vessel as an
arrow from its centre of mass (:data:`FORCE_SCALE` m per N), the predicted and measured landing points, and at the
end the pourer lip's commanded path over the whole run. The 3-D view's camera is framed at the end on everything the
vessels and the stream occupied over the run (:func:`pour_camera`). The controller's log has its phase changes and,
while it pours (CFS), its state every :data:`STATUS_PERIOD` s.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np

from cosim.coupling.exchange import ROLES
from cosim.coupling.loop import CoupledPour
from cosim.frames import tilt_about_y
from cosim.io.rerun_framing import frame_points, geom_box_corners
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole

# m of arrow per N of the liquid's force (a litre of water weighs 9.8 N: a 10 cm arrow).
FORCE_SCALE = 0.01
# s of simulated time between the controller's state lines while it pours.
STATUS_PERIOD = 0.5
# Phases in which the controller holds the flow (its state is logged every STATUS_PERIOD).
POURING_PHASES = ("cfs", "cfs_final")
# rad: the default camera's elevation above the pour plane's normal (enough to see into the catcher).
VIEW_ELEVATION = math.radians(20.0)
# m: drawn radius of the landing points and of the lip path.
LANDING_RADIUS = 0.008
PATH_RADIUS = 0.002
PREDICTED_COLOR = (255, 140, 0, 255)
MEASURED_COLOR = (220, 30, 200, 255)
PATH_COLOR = (255, 200, 0, 255)
FORCE_COLOR = (230, 60, 40, 255)


def vessel_geoms(scene: RobotScene) -> np.ndarray:
    """Ids of the geoms of both vessels' bodies (their walls and floors)."""
    bodies = [scene.arms[role].vessel_body for role in ROLES]
    return np.flatnonzero(np.isin(scene.model.geom_bodyid, bodies))


def pour_camera(scene: RobotScene, points: np.ndarray):
    """The default camera on the pour whose vessels and stream occupied ``points`` ((n, 3) m, world frame: the
    corners of the vessels' geoms, the lip's path, the landing points): looking at the middle of their bounding box
    from the side of the pour plane opposite the pour arm's shoulder (whose links would hide the pourer), raised by
    :data:`VIEW_ELEVATION`, as near as lets them fill most of the view (:func:`cosim.io.rerun_framing.frame_points`)."""
    shoulder = scene.data.xpos[scene.model.jnt_bodyid[scene.model.joint(scene.arms[ArmRole.POUR].joints[0]).id]]
    middle_y = 0.5 * (points[:, 1].min() + points[:, 1].max())
    side = -1.0 if shoulder[1] > middle_y else 1.0
    return frame_points(points, np.array([0.0, side * math.cos(VIEW_ELEVATION), math.sin(VIEW_ELEVATION)]))


def open_recorder(pour: CoupledPour, path: Path, settings, name: str, scene_toml: str):
    """The :class:`~cosim.io.recording.PourRecorder` of ``pour`` at ``path``: named ``name``, the scene's TOML and
    the liquid's dimension and particle count as properties, the vessel frames as tool frames (its camera is set by
    :meth:`PourRecordingFeed.finish`); ``settings``: the scene's :class:`~cosim.io.recording_config.RecordingConfig`."""
    from cosim.io.recording import PourRecorder

    scene, fluid = pour.scene, pour.fluid
    frames = [scene.model.site(scene.arms[role].frame_site).name for role in ROLES]
    dim = fluid.config.dim
    note = (
        "2-D liquid: drawn is the pour-plane slice (y = 0); the liquid is as deep as the vessel holding it "
        f"({1e3 * fluid.config.depth_2d:g} mm in the pourer and in the stream; the catcher's depth once caught)."
        if dim == 2 else ""
    )
    return PourRecorder(
        path, scene.model, settings, particle_radius=0.5 * fluid.config.spacing, name=name,
        properties={"scene_name": name, "dim": dim, "particles": fluid.n_particles, "scene_toml": scene_toml},
        frames=frames, liquid_note=note,
    )


class PourRecordingFeed:
    """Feeds the recorder from the pour (call it after every step, :meth:`finish` at the end): states at the
    recording rate, signals and the controller's log at control steps; and keeps the points (``framed``, m, world
    frame) of everything the vessels (their geoms' box corners at every logged state) and the stream (the lip's path
    and the landing points) occupied, on which :meth:`finish` frames the camera."""

    def __init__(self, pour: CoupledPour, recorder):
        self.pour, self.rec = pour, recorder
        self.fk = mujoco.MjData(pour.scene.model)
        self.phase = None
        self.rows = 0
        self.next_status = -math.inf
        self.lip_path: list[np.ndarray] = []
        self.vessel_geoms = vessel_geoms(pour.scene)
        self.framed: list[np.ndarray] = []

    def commanded_pose(self) -> tuple[float, np.ndarray]:
        """Pourer tilt (rad) and lip position (3,) m of the commanded joint trajectory at its current time (forward
        kinematics)."""
        scene, fk = self.pour.scene, self.fk
        for role in ROLES:
            fk.qpos[scene.arms[role].qpos_adr] = self.pour.generators[role].state[0]
        mujoco.mj_kinematics(scene.model, fk)
        arm = scene.arms[ArmRole.POUR]
        return tilt_about_y(fk.xmat[arm.vessel_body].reshape(3, 3)), fk.site_xpos[arm.lip_site].copy()

    def __call__(self, pour: CoupledPour) -> None:
        t, step = pour.time, pour.steps
        if self.rec.state_due(t):
            self.log_state(force=False)
        rows = pour.log.rows
        if len(rows.get("t", ())) == self.rows:
            return
        self.rows = len(rows["t"])
        theta, lip = self.commanded_pose()
        self.lip_path.append(lip)
        self.rec.log_scalars(pour.generators[ArmRole.POUR].time, step, self.signals(theta))
        phase = rows["phase"][-1]
        if phase != self.phase:
            self.phase = phase
            reason = pour.command.reason if pour.command else ""
            self.rec.log_phase(t, step, phase, reason)
            self.next_status = t
        if phase in POURING_PHASES and t >= self.next_status - 1e-9:
            self.rec.log_text(t, step, self.status(), level="DEBUG")
            self.next_status = t + STATUS_PERIOD

    def signals(self, theta: float) -> dict:
        """The scalar signals of the last control step (see the module docstring); ``theta``: commanded tilt, rad."""
        pour, rows = self.pour, self.pour.log.rows
        in_pourer, in_catcher = rows["volume_in_pourer"][-1], rows["volume_in_catcher"][-1]
        values = {
            "pour/tilt_deg": {
                "commanded": math.degrees(theta), "measured": math.degrees(rows["tilt"][-1]),
                "surface theta1": math.degrees(rows["theta1"][-1]),
            },
            "pour/head_over_crest_mm": 1e3 * rows["h_q"][-1],
            "pour/outflow_speed_m_s": rows["v_q"][-1],
            "pour/volume_mL": {
                "in pourer": 1e6 * in_pourer, "in catcher": 1e6 * in_catcher,
                "outside": 1e6 * (pour.geometry.initial_volume - in_pourer - in_catcher),
            },
            "pour/landing_x_mm": {"predicted": 1e3 * rows["landing_x"][-1], "measured": 1e3 * rows["landing_measured_x"][-1]},
        }
        for vessel, w in (("pourer", rows["wrench_pourer"][-1]), ("catcher", rows["wrench_catcher"][-1])):
            values[f"{vessel}/liquid_force_N"] = {axis: float(w[k]) for k, axis in enumerate("xyz")}
            values[f"{vessel}/liquid_torque_N_m"] = {axis: float(w[3 + k]) for k, axis in enumerate("xyz")}
        for role in ROLES:
            q, qd, _ = pour.generators[role].state
            joints = [j.split("/")[-1] for j in pour.scene.arms[role].joints]
            values[f"{role.value}/joint_angle_deg"] = dict(zip(joints, np.degrees(q).tolist()))
            values[f"{role.value}/joint_speed_deg_s"] = dict(zip(joints, np.degrees(qd).tolist()))
        return values

    def status(self) -> str:
        """The controller's state as one line: head over the crest, outflow speed and rate, tilt, poured volume."""
        rows = self.pour.log.rows
        poured = rows["poured_volume"]
        k = max(0, len(poured) - 1 - round(STATUS_PERIOD / self.pour.controller.dt))
        span = rows["t"][-1] - rows["t"][k]
        rate = (poured[-1] - poured[k]) / span if span > 0 else 0.0
        return (
            f"{rows['phase'][-1]}: head {1e3 * rows['h_q'][-1]:.1f} mm, outflow {rows['v_q'][-1]:.2f} m/s "
            f"({1e6 * rate:.0f} mL/s), tilt {math.degrees(rows['tilt'][-1]):.1f} deg, poured {1e6 * poured[-1]:.0f} mL"
        )

    def log_state(self, force: bool) -> None:
        """Body poses, liquid, the liquid's force on each vessel and the landing points, now."""
        pour = self.pour
        t, step, data, fluid = pour.time, pour.steps, pour.scene.data, pour.fluid
        if not self.rec.log_state(t, step, data, fluid.positions(), np.linalg.norm(fluid.velocities(), axis=1),
                                  active=fluid.active_mask(), force=force):
            return
        self.framed.append(geom_box_corners(pour.scene.model, data, self.vessel_geoms))
        origins = np.array([data.xipos[pour.scene.arms[role].vessel_body] for role in ROLES])
        forces = pour.wrench[:, :3]
        labels = [f"{np.linalg.norm(f):.1f} N on {pour.scene.arms[role].vessel.name}" for f, role in zip(forces, ROLES)]
        self.rec.log_arrows(t, step, "liquid_force", origins, FORCE_SCALE * forces, labels, FORCE_COLOR)
        rows = pour.log.rows
        if not rows.get("t"):
            return
        catcher_y = data.site_xpos[pour.scene.arms[ArmRole.CATCH].frame_site][1]
        rim_z = rows["catcher_rim_z"][-1]
        for name, x, color in (("predicted", rows["landing_x"][-1], PREDICTED_COLOR),
                               ("measured", rows["landing_measured_x"][-1], MEASURED_COLOR)):
            points = np.array([[x, catcher_y, rim_z]]) if np.isfinite(x) else np.zeros((0, 3))
            self.framed.append(points)
            self.rec.log_points(t, step, f"landing/{name}", points, LANDING_RADIUS, color, f"{name} landing")

    def finish(self) -> None:
        """Log the final state and the lip's commanded path over the whole run, and frame the 3-D view's camera on
        the whole run (:func:`pour_camera`)."""
        self.log_state(force=True)
        if len(self.lip_path) > 1:
            self.rec.log_path("lip_path/commanded", np.array(self.lip_path), PATH_COLOR, PATH_RADIUS, "commanded lip path")
        self.rec.camera = pour_camera(self.pour.scene, np.concatenate([*self.framed, np.reshape(self.lip_path, (-1, 3))]))
