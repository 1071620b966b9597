"""A pure-numpy stand-in for the SPH liquid, to exercise the controllers in closed loop (tests, model figures).

The liquid is the first-mode slosh pendulum (:meth:`controllers.slosh.SloshModel.state_space`, driven by the
world motion of its hinge; model (M) for small tilts) plus the box geometry: the free surface is the vessel-frame line of slope tan(theta1) that
bounds the liquid's area (:mod:`controllers.geometry`); h_q is that line's height over the crest; the outflow
is the sharp-crested weir per unit depth q = (2/3) C_d sqrt(2 g) h_q^(3/2) with v_q = q / h_q
(Camporredondo et al. 2019, Sec. 2.2).
Limits: linear slosh with the pendulum of the initial fill, no damping, no vertical-acceleration effect, no
spill over the back wall, tilts below 90 deg. The arm is ideal: the pose moves linearly from one command to
the next over one control period (a one-period lag), or carries out each command ``arm_delay_steps`` periods
late (a slow arm, like the coupled pour's smoothed one).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import control as ct
import numpy as np

from controllers.catcher import weir_velocity
from controllers.config import CatcherConfig, PourConfig
from controllers.geometry import PlanarPose, VesselGeometry, height_above, surface_offset
from controllers.measurement import LiquidMeasurement, PourCommand
from controllers.pour import PourController
from controllers.slosh import SloshModel, potential_flow_model
from declared_settings.setting import check_settings, documented, like, setting


PLANT = "model plant"


@documented
@dataclass(frozen=True)
class ModelPlantConfig:
    """The stand-in's scene, the pour's settings (:class:`controllers.config.PourConfig`) where it shares them.

    vessel: the pourer's :class:`controllers.geometry.VesselGeometry`.
    slosh: the liquid's first-mode pendulum; None: potential flow for the box and fill.
    """

    vessel: VesselGeometry = field(default_factory=VesselGeometry)
    fill_depth: float = like(PourConfig, "fill_depth")
    home_x: float = setting(0.0, PLANT, "World x of the pourer's vessel-frame origin at home.", "m")
    home_z: float = setting(0.30, PLANT, "World z of the pourer's vessel-frame origin at home.", "m")
    catcher_rim_z: float = setting(0.20, PLANT, "World z of vessel B's rim.", "m")
    discharge_coefficient: float = like(CatcherConfig, "discharge_coefficient")
    substeps: int = setting(10, PLANT, "Integration steps per control period (the input is interpolated linearly).", "",
                            1, 100)
    gravity: float = like(PourConfig, "gravity")
    arm_delay_steps: int = setting(0, PLANT, "Control periods by which the arm carries out each command late.", "",
                                   0, 100)
    slosh: SloshModel | None = None

    def __post_init__(self) -> None:
        check_settings(self, "plant")


class ModelPlant:
    """Stand-in liquid + ideal arm. :meth:`measure` then :meth:`advance` once per control period ``dt`` (s)."""

    def __init__(self, config: ModelPlantConfig, dt: float) -> None:
        self.config = config
        geom = config.vessel
        self.model = config.slosh or potential_flow_model(geom.inner_width, config.fill_depth, config.gravity, geom.shape)
        self._h = dt / config.substeps
        sysd = ct.c2d(self.model.state_space(), self._h, "zoh")
        self._a, self._b = np.asarray(sysd.A), np.asarray(sysd.B)
        self._c, self._d = np.asarray(sysd.C)[0], np.asarray(sysd.D)[0]
        self._state = np.zeros(2)  # at rest at home: hinge x offset 0, sigma = 0
        self.dt = dt
        self.t = 0.0
        self.pose = PlanarPose()
        self.area = geom.inner_width * config.fill_depth  # m^2 in the pour plane
        self.poured = 0.0  # m^3
        self._pending: deque[PlanarPose] = deque()  # commands not yet carried out (arm_delay_steps of them)

    def _hinge_x(self, pose: PlanarPose) -> np.ndarray:
        """World x offset (m) of the pendulum's hinge, the slosh model's input."""
        return np.array([pose.point((0.0, self.model.hinge_height))[0]])

    def _theta1(self, pose: PlanarPose) -> float:
        return pose.theta + float(self._c @ self._state + self._d @ self._hinge_x(pose))

    def _h_q(self, pose: PlanarPose, theta1: float) -> float:
        geom = self.config.vessel
        c = surface_offset(geom.inner_width, math.tan(theta1), self.area)
        return height_above(geom.crest, c, theta1, pose.theta)

    def measure(self) -> LiquidMeasurement:
        cfg, pose = self.config, self.pose
        theta1 = self._theta1(pose)
        h_q = self._h_q(pose, theta1)
        lip_dx, lip_dz = pose.point(cfg.vessel.lip)
        return LiquidMeasurement(
            t=self.t,
            tilt=pose.theta,
            theta1=theta1,
            h_q=h_q,
            v_q=weir_velocity(h_q, cfg.discharge_coefficient, cfg.gravity),
            volume_in_pourer=self.area * cfg.vessel.inner_depth,
            poured_volume=self.poured,
            lip_x=cfg.home_x + lip_dx,
            lip_z=cfg.home_z + lip_dz,
            catcher_rim_z=cfg.catcher_rim_z,
        )

    def advance(self, target: PlanarPose) -> None:
        """Move the vessel linearly from its pose to ``target`` (the command given arm_delay_steps periods ago)
        over one period and integrate the liquid."""
        cfg, start = self.config, self.pose
        self._pending.append(target)
        if len(self._pending) <= cfg.arm_delay_steps:
            target = start
        else:
            target = self._pending.popleft()
        weir = (2.0 / 3.0) * cfg.discharge_coefficient * math.sqrt(2.0 * cfg.gravity)
        for i in range(1, cfg.substeps + 1):
            f = i / cfg.substeps
            pose = PlanarPose(
                start.dx + f * (target.dx - start.dx),
                start.dz + f * (target.dz - start.dz),
                start.theta + f * (target.theta - start.theta),
            )
            self._state = self._a @ self._state + self._b @ self._hinge_x(pose)
            h_q = self._h_q(pose, self._theta1(pose))
            out = min(weir * max(h_q, 0.0) ** 1.5 * self._h, self.area)
            self.area -= out
            self.poured += out * cfg.vessel.inner_depth
        self.pose = target
        self.t += self.dt


@dataclass
class Trace:
    """Time series of a closed-loop run (one entry per control step)."""

    measurements: list[LiquidMeasurement] = field(default_factory=list)
    commands: list[PourCommand] = field(default_factory=list)

    def series(self, name: str) -> np.ndarray:
        """A measurement field (e.g. "theta1", "h_q") as an array."""
        return np.array([getattr(m, name) for m in self.measurements])

    @property
    def t(self) -> np.ndarray:
        return self.series("t")


def run_closed_loop(controller: PourController, plant: ModelPlant, duration: float) -> Trace:
    """Run controller and stand-in plant for ``duration`` s or until the pour is done."""
    trace = Trace()
    while plant.t <= duration:
        m = plant.measure()
        cmd = controller.step(m)
        trace.measurements.append(m)
        trace.commands.append(cmd)
        if cmd.done:
            break
        plant.advance(cmd.pourer)
    return trace
