"""The co-simulation step loop: MuJoCo arms holding the vessels, the SPH liquid in them, the pour controller.

Exchange order of one MuJoCo step n (t_n -> t_n+1 = t_n + dt, dt = the model's timestep, 2 ms, implicitfast):

  1. every control period (10 ms): measure the liquid at t_n -> controller -> vessel targets -> IK -> the arms'
     trajectory generators get new joint targets;
  2. each arm's generator advances one dt -> desired q, qd for the servos (plus, with two-way coupling, the
     compensation of the liquid the arm's controller knows of: by default its payload setting, the liquid at the
     start; :mod:`cosim.coupling.compensation`);
  3. two-way: the liquid's wrench on each vessel averaged over [t_n-1, t_n] goes into ``xfrc_applied``;
  4. ``mj_step``: the arms and vessels move to t_n+1;
  5. the vessel poses at t_n+1 go to the fluid, which moves the walls from their t_n poses to them at constant
     velocity over as many substeps as its CFL step needs; the wrench averaged over those substeps is kept for
     step n+1 (explicit staggered coupling).

Alongside, :class:`cosim.coupling.arm_load.ArmLoadMonitor` steps a twin of the arms without the liquid to measure the
vessel deviation the liquid causes and records the drives' peak torques, and the wrench of every step is kept for the
inverse dynamics of the exported trajectory (:meth:`CoupledPour.sample_wrenches`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import mujoco
import numpy as np

from controllers.config import CatcherConfig, PourConfig
from controllers.geometry import VesselGeometry
from controllers.measurement import Phase, PourCommand
from controllers.pour import PourController
from controllers.catcher import fall_time
from cosim.coupling.arm_load import ArmLoadMonitor
from cosim.coupling.compensation import Payload, compensation_torque, liquid_payload
from cosim.coupling.exchange import ROLES, vessel_poses, wrench_at_body_com
from cosim.coupling.landing import landing_accuracy
from cosim.coupling.outflow import outflow_timing
from cosim.coupling.measure import LiquidProbe, MeasurementGeometry
from cosim.coupling.pose_filter import SMOOTHING_DELAY, PoseFilter, PoseFilterLimits, PoseSmoother
from cosim.coupling.settings import Compensation, Coupling, CouplingSettings
from cosim.fluid.config import FluidConfig
from cosim.fluid.seeding import fill_vessel
from cosim.fluid.solver import FluidSolver
from cosim.frames import Pose
from cosim.robots.ik import ArmIK, IKSettings
from cosim.robots.planar import PlanarPose
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from cosim.robots.vessel_mjcf import frame_site
from cosim.trajectory.generator import GeneratorSettings, TrajectoryGenerator
from cosim.trajectory.limits import ArmLimits
from cosim.trajectory.recorder import TrajectoryRecorder
from cosim.trajectory.sampling import DEFAULT_SAMPLE_RATE_HZ

CATCHER_TRAVEL = 0.15  # m each way along x: the catcher workspace the robot scene's IK is verified over
# IK of the smoothed vessel targets: converged far below the trajectory checks' tolerances (looser solves add
# solver noise that shows up as joint acceleration, trajectory tests).
TARGET_IK = IKSettings(position_tolerance=1e-10, rotation_tolerance=1e-10, max_iterations=200)
# The phases whose pourer path the pose smoothing does not delay (cosim.coupling.pose_filter.PoseSmoother): the slosh
# damping, a feedback loop designed with the arm's known delay. The excitation and the hold before it go through the
# smoothing like every other path: the jerk-limited filter re-plans a stop at every excitation target and, where it
# catches up with a small excitation, follows it bang-bang in jerk at the control rate, the ripple the smoothing
# stages roll off. Their delay is taken out where the command's path ahead is known (the excitation's): the filter
# is fed the command SMOOTHING_DELAY early, so that the arm tilts when it did without the stages (the hold's end
# is timed by the slosh against the vessel's measured tilt).
UNDELAYED = (Phase.SIM_DAMP,)
# The phases whose targets move on every period (the CFS law's tilt and the catcher's landing point): the pose filter
# tracks them instead of approaching each as a target to stop at (cosim.coupling.pose_filter.PoseFilter).
TRACKED = (Phase.CFS, Phase.CFS_FINAL)


def coupled_step(
    scene: RobotScene,
    fluid: FluidSolver,
    wrench: np.ndarray,
    targets: dict[ArmRole, tuple[np.ndarray, np.ndarray | None]],
    settings: CouplingSettings,
    payloads: dict[ArmRole, Payload] | None = None,
    frames: list[Pose] | None = None,
) -> tuple[np.ndarray, list[Pose]]:
    """Steps 2-5 of the exchange order above for one MuJoCo step: servo targets ``(q, qd)`` per arm (+ the
    compensation ``settings.compensation`` of ``wrench``, the liquid's (2, 6) wrench from the previous interval, or of
    the arms' ``payloads``), the wrench into MuJoCo (two-way), ``mj_step``, then the fluid over the same dt; returns
    the new averaged wrench (2, 6) and the vessel frames' world poses after the step, which the next step takes as
    ``frames`` (None: read from the scene, whose kinematics must be those of its current configuration, as
    ``mj_forward`` leaves them)."""
    two_way = settings.coupling is Coupling.TWO_WAY
    poses = fluid.vessel_poses()
    if frames is None:
        frames = vessel_poses(scene)
    for k, role in enumerate(ROLES):
        q, qd = targets[role]
        force, torque = wrench_at_body_com(scene, role, poses[k], wrench[k])
        payload = payloads.get(role) if payloads else None
        tau_ff = compensation_torque(scene, role, settings.compensation, force, torque, payload, frames[k]) if two_way else None
        scene.set_joint_targets(role, q, qd, tau_ff)
        if two_way:
            scene.apply_vessel_wrench(role, force, torque)
    dt = float(scene.model.opt.timestep)
    mujoco.mj_step(scene.model, scene.data)
    # mj_step leaves the body frames at the step's start (its forward pass runs before the integration): bring them,
    # and the Jacobians' frame (mj_comPos), to the new qpos so the liquid's target is the pose at t + dt.
    mujoco.mj_kinematics(scene.model, scene.data)
    mujoco.mj_comPos(scene.model, scene.data)
    frames = vessel_poses(scene)
    fluid.set_vessel_poses(frames)
    fluid.advance(dt)
    return fluid.vessel_wrenches(), frames


@dataclass
class PourLog:
    """Per control step records (lists, turned into arrays by :meth:`arrays`)."""

    rows: dict[str, list] = field(default_factory=dict)

    def append(self, **values) -> None:
        for k, v in values.items():
            self.rows.setdefault(k, []).append(v)

    def arrays(self) -> dict[str, np.ndarray]:
        return {k: np.asarray(v) for k, v in self.rows.items()}


class CoupledPour:
    """One pour: build with :func:`build_pour`, then :meth:`run` (or :meth:`step` repeatedly)."""

    def __init__(
        self,
        scene: RobotScene,
        fluid: FluidSolver,
        controller: PourController,
        limits: dict[ArmRole, ArmLimits],
        geometry: MeasurementGeometry,
        settings: CouplingSettings,
        pose_limits: PoseFilterLimits = PoseFilterLimits(),
        sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ,
    ):
        self.scene, self.fluid, self.controller = scene, fluid, controller
        dt = float(scene.model.opt.timestep)
        gen_settings = GeneratorSettings(cycle_time=dt, control_period=controller.dt, stop_beyond_velocity_limit=True)
        self.generators = {r: TrajectoryGenerator(limits[r], scene.joint_positions(r), gen_settings) for r in ROLES}
        self.recorder = TrajectoryRecorder([self.generators[r] for r in ROLES], sample_rate_hz)
        self.filters = {
            ArmRole.POUR: PoseFilter("pourer_pose", ("dx", "dz", "theta"), pose_limits, controller.dt),
            ArmRole.CATCH: PoseFilter("catcher_pose", ("dx",), pose_limits, controller.dt),
        }
        self.smoothers = {role: PoseSmoother(self.filters[role].coordinates, controller.dt) for role in ROLES}
        self._ik = {r: ArmIK(scene.model, scene.arms[r].joints, frame_site(scene.arms[r].vessel), scene.arms[r].home_q, TARGET_IK) for r in ROLES}
        self.geometry = geometry
        self.probe = LiquidProbe(geometry, fluid.n_particles, fluid.device)
        self.settings = settings
        self.dt = float(scene.model.opt.timestep)
        self.control_every = max(1, round(controller.dt / self.dt))
        self.steps = 0
        self.time = 0.0
        self.wrench = np.zeros((2, 6))
        self.command: PourCommand | None = None
        self.done_at: float | None = None
        self.log = PourLog()
        self.wall_time = 0.0
        self._seed = {role: scene.joint_positions(role) for role in ROLES}
        self.payloads = {role: self._payload(role, volume) for role, volume in zip(ROLES, (geometry.initial_volume, 0.0))}
        self.arm_load = ArmLoadMonitor(scene)
        self.wrench_history: list[np.ndarray] = []  # (2, 6) the liquid's wrench acting during each MuJoCo step
        self._frames: list[Pose] | None = None  # the vessel frames' world poses at the arms' current configuration

    def _payload(self, role: ArmRole, volume: float) -> Payload:
        """The payload setting of ``role``'s arm for ``volume`` (m^3) of liquid in its vessel."""
        return liquid_payload(self.scene.arms[role].vessel, volume, self.fluid.config.rest_density)

    # ---- one MuJoCo step -----------------------------------------------------------------------------------------
    def step(self) -> None:
        start = time.perf_counter()
        scene = self.scene
        if self.steps % self.control_every == 0:
            self._control()
        targets = {}
        for role in ROLES:
            q, qd, _ = self.generators[role].step()
            targets[role] = (q, qd)
        self.recorder.record()
        self.wrench_history.append(self.wrench)
        self.wrench, self._frames = coupled_step(scene, self.fluid, self.wrench, targets, self.settings, self.payloads, self._frames)
        self.arm_load.step(targets)
        self.steps += 1
        self.time = self.steps * self.dt
        if self.command is not None and self.command.done and self.done_at is None:
            self.done_at = self.time
        self.wall_time += time.perf_counter() - start

    def _control(self) -> None:
        fluid, scene = self.fluid, self.scene
        poses = fluid.vessel_poses()
        last = fluid.last_report.last if fluid.last_report else None
        in_pourer = last.volume_in_vessel[0] if last else self.geometry.initial_volume
        if last and self.settings.compensation is Compensation.UPDATED_PAYLOAD:
            self.payloads = {role: self._payload(role, volume) for role, volume in zip(ROLES, last.volume_in_vessel)}
        state = fluid.state  # the device arrays as they are: the probe reads them where they live
        m = self.probe.measure(self.time, poses[0], poses[1], state.x, state.v, state.active, in_pourer)
        cmd = self.controller.step(m)
        self.command = cmd
        targets = {ArmRole.POUR: cmd.pourer, ArmRole.CATCH: cmd.catcher}
        smoothed = {}
        for role in ROLES:
            t = targets[role]
            if role is ArmRole.POUR and cmd.pourer_ahead is not None:
                t = cmd.pourer_ahead(SMOOTHING_DELAY)
            limited = self.filters[role](
                PlanarPose(t.dx, t.dz, t.theta), pass_through=role is ArmRole.POUR and cmd.feedback, track=cmd.phase in TRACKED,
            )
            passed = self.filters[role].passing
            undelayed = passed or (role is ArmRole.POUR and cmd.phase in UNDELAYED)
            pose = self.smoothers[role](limited, passing=undelayed, source="command" if passed else "limited")
            smoothed[role] = pose
            pos, quat = scene.vessel_target(role, pose)
            label = f"{scene.arms[role].vessel.name} target (dx={pose.dx:.3f} m, dz={pose.dz:.3f} m, tilt={math.degrees(pose.theta):.1f} deg)"
            q = self._ik[role].solve_or_raise(pos, quat, self._seed[role], label)
            self._seed[role] = q
            self.generators[role].set_target(q)
        in_catcher = last.volume_in_vessel[1] if last else 0.0
        gravity = self.fluid.config.gravity_magnitude
        flowing = m.h_q > 0.0 and m.v_q > 0.0
        crossing = self.probe.stream_crossing_x(state.x, state.v, state.active, m.catcher_rim_z, m.lip_z, gravity)
        self.log.append(
            t=self.time, tilt=m.tilt, theta1=m.theta1, h_q=m.h_q, v_q=m.v_q, v_q_z=m.v_q_z,
            volume_in_pourer=in_pourer, volume_in_catcher=in_catcher, poured_volume=m.poured_volume,
            spilled_volume=last.spilled_volume if last else 0.0, lip_x=m.lip_x, lip_z=m.lip_z, jet_dx=m.jet_dx, jet_dz=m.jet_dz,
            landing_x=cmd.landing_x, landing_measured_x=crossing,
            landing_fall_time=fall_time(m.lip_z + m.jet_dz - m.catcher_rim_z, m.v_q_z, gravity) if flowing else math.nan,
            catcher_rim_z=m.catcher_rim_z, phase=cmd.phase.value, target_theta=cmd.pourer.theta, target_dx=cmd.pourer.dx,
            target_dz=cmd.pourer.dz, smoothed_theta=smoothed[ArmRole.POUR].theta, catcher_dx=cmd.catcher.dx,
            smoothed_catcher_dx=smoothed[ArmRole.CATCH].dx, wrench_pourer=self.wrench[0].copy(),
            wrench_catcher=self.wrench[1].copy(),
        )

    # ---- whole run -----------------------------------------------------------------------------------------------
    @property
    def finished(self) -> bool:
        if self.time >= self.settings.max_duration - 1e-12:
            return True
        if not self.settings.stop_when_done or self.done_at is None:
            return False
        return self.time >= self.done_at + self.settings.settle_time - 1e-12

    def run(self, on_step: Callable[["CoupledPour"], None] | None = None) -> dict:
        while not self.finished:
            self.step()
            if on_step is not None:
                on_step(self)
        return self.summary()

    def landing_accuracy(self) -> dict:
        """Predicted against measured landing x of the stream in CFS, its final stage included
        (:func:`cosim.coupling.landing.landing_accuracy`)."""
        rows = self.log.arrays()
        if "t" not in rows:
            return {"samples": 0}
        return landing_accuracy(rows["t"], rows["landing_x"], rows["landing_fall_time"], rows["landing_measured_x"],
                                np.isin(rows["phase"], ("cfs", "cfs_final")))

    def outflow_timing(self) -> dict:
        """First and steady outflow (s after the pour's start), :func:`cosim.coupling.outflow.outflow_timing`."""
        rows = self.log.arrays()
        if "t" not in rows:
            return outflow_timing([], [], [], 0.0)
        return outflow_timing(rows["t"], rows["poured_volume"], rows["phase"] == "cfs", self.controller.config.start_time)

    def sample_wrenches(self, times: np.ndarray) -> dict[ArmRole, np.ndarray]:
        """Per arm, (T, 6): the liquid's wrench (as :meth:`FluidSolver.vessel_wrenches`) acting on the vessel at each
        of ``times`` (s, on the generators' clock): that of the MuJoCo step starting there (the last step's at the
        end)."""
        history = np.array(self.wrench_history)
        index = np.clip(np.floor(np.asarray(times) / self.dt + 1e-6).astype(int), 0, len(history) - 1)
        return {role: history[index, k] for k, role in enumerate(ROLES)}

    def summary(self) -> dict:
        """Volumes (m^3), phases (name, start s, end s), times (s) of the run so far; ``energy_created``: the most
        energy the SPH numerics had created at any time, over M g L (``cosim.fluid.energy``; the run stops with an
        instability past ``fluid.max_energy_creation``); ``guard_corrections``: how many times the non-penetration
        guard put a particle back on a wall face it was entering (summed over the substeps; the guard is a last
        resort, so this counts what the wall particles' pressure alone did not hold back).

        A partial pour (the controller's ``target_volume`` set) reports its ``target_volume`` (m^3) and how far the
        poured volume missed it: ``target_error`` = poured - target (m^3, > 0: poured too much) and
        ``target_relative_error`` = target_error / target; all three are None for a pour until empty."""
        last = self.fluid.last_report.last
        initial = self.geometry.initial_volume
        in_pourer, in_catcher = last.volume_in_vessel
        poured = initial - in_pourer
        spilled = max(initial - in_pourer - in_catcher, 0.0)  # volumes are particle counts x volume: -1e-19 is 0
        target = self.controller.config.target_volume
        return {
            "initial_volume": initial,
            "volume_left_in_pourer": in_pourer,
            "target_volume": target,
            "target_error": None if target is None else poured - target,
            "target_relative_error": None if target is None else (poured - target) / target,
            "poured_volume": poured,
            "caught_volume": in_catcher,
            "spilled_volume": spilled,
            "left_domain_volume": last.spilled_volume,
            "spilled_fraction_of_poured": spilled / poured if poured > 0 else 0.0,
            "phases": [{"phase": p, "start": a, "end": b} for p, a, b in self.controller.phase_intervals(self.time)],
            "transitions": [
                {"time": tr.t, "from": tr.source.value, "to": tr.target.value, "reason": tr.reason}
                for tr in self.controller.transitions
            ],
            "landing": self.landing_accuracy(),
            "outflow": self.outflow_timing(),
            "pour_done": self.done_at is not None,
            "sim_time": self.time,
            "wall_time": self.wall_time,
            "real_time_factor": self.time / self.wall_time if self.wall_time > 0 else float("nan"),
            "mujoco_steps": self.steps,
            "sph_steps": self.fluid.step_count,
            "particles": self.fluid.n_particles,
            "energy_created": self.fluid.energy_account.peak_created,
            "guard_corrections": int(self.fluid.history().get("wall_corrections", np.zeros(0, dtype=int)).sum()),
            "arm_load": {
                role.value: {
                    "compensation": self.settings.compensation.value if self.settings.coupling is Coupling.TWO_WAY else "one_way",
                    "liquid_deviation_mm": 1e3 * self.arm_load.max_position[role],
                    "liquid_deviation_deg": math.degrees(self.arm_load.max_rotation[role]),
                    "peak_servo_torque": dict(zip(self.scene.arms[role].joints, self.arm_load.peak_torque[role].tolist())),
                }
                for role in ROLES
            },
        }


def pour_fluid_config(scene: RobotScene, base: FluidConfig, fill_depth: float) -> FluidConfig:
    """``base`` with the domain and the expected speed of this scene: the domain spans both vessels and the
    catcher's travel, its floor just below the catcher (liquid that misses falls out and counts as spilled);
    the expected speed is the larger of the jet's speed at the catcher floor and 2 sqrt(g A)."""
    pour, catch = scene.arms[ArmRole.POUR], scene.arms[ArmRole.CATCH]
    p, c = pour.home_pos, catch.home_pos
    reach = max(pour.vessel.inner_height, pour.vessel.inner_width) + 0.15
    lo = (min(p[0], c[0]) - reach, -0.5 * max(pour.vessel.section_depth, catch.vessel.section_depth) - 0.2, c[2] - catch.vessel.wall_thickness - 0.05)
    hi = (max(p[0], c[0]) + CATCHER_TRAVEL + reach, -lo[1], p[2] + pour.vessel.inner_height + reach)
    fall = p[2] + pour.vessel.inner_height - c[2]
    g = base.gravity_magnitude
    speed = max(math.sqrt(2.0 * g * fall), 2.0 * math.sqrt(g * fill_depth))
    fields = {f: getattr(base, f) for f in base.__dataclass_fields__}
    fields.update(domain_min=lo, domain_max=hi, max_expected_speed=speed, depth_2d=pour.vessel.section_depth)
    return FluidConfig(**fields)


def build_pour(
    scene: RobotScene,
    fluid_base: FluidConfig,
    pour_config: Callable[[VesselGeometry, CatcherConfig, float, float], PourConfig],
    limits: dict[ArmRole, ArmLimits],
    fill_depth: float,
    settings: CouplingSettings = CouplingSettings(),
    device: str = "cpu",
    pose_limits: PoseFilterLimits = PoseFilterLimits(),
    sample_rate_hz: float = DEFAULT_SAMPLE_RATE_HZ,
) -> CoupledPour:
    """Assemble a pour: the liquid filling the pourer at home to ``fill_depth``, the controller (built by
    ``pour_config(vessel_geometry, catcher_config, actual_fill_depth, initial_volume)``), the arms' trajectory
    generators under ``limits``.

    The controller gets the liquid's actual fill (the lattice holds whole layers) and the wall thickness the
    liquid sees, so its geometry is the simulated one."""
    cfg = pour_fluid_config(scene, fluid_base, fill_depth)
    specs = [scene.arms[r].vessel for r in ROLES]
    poses = vessel_poses(scene)
    particles = fill_vessel(specs[0], fill_depth, cfg, poses[0])
    fluid = FluidSolver(cfg, specs, poses, particles, device=device)
    pourer = specs[0]
    wall = float(fluid.model.wall_thickness[0])
    initial_volume = fluid.n_particles * cfg.particle_volume
    depth = pourer.liquid_depth(cfg.dim)
    actual_fill = initial_volume / (pourer.inner_width * depth)
    geometry = VesselGeometry(pourer.inner_width, pourer.inner_height, wall, depth, pourer.liquid_shape(cfg.dim).value)
    catcher = CatcherConfig(home_x=float(scene.arms[ArmRole.CATCH].home_pos[0]), travel_min=-CATCHER_TRAVEL, travel_max=CATCHER_TRAVEL)
    controller = PourController(pour_config(geometry, catcher, actual_fill, initial_volume))
    mgeo = MeasurementGeometry(pourer, wall, specs[1].inner_height, cfg.smoothing_length, cfg.spacing, initial_volume, cfg.dim)
    return CoupledPour(scene, fluid, controller, limits, mgeo, settings, pose_limits, sample_rate_hz)
