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
from controllers.checks import check_range
from controllers.errors import ControllerInputError
from controllers.geometry import PlanarPose, VesselGeometry, height_above, surface_offset
from controllers.measurement import LiquidMeasurement, PourCommand
from controllers.pour import PourController
from controllers.slosh import GRAVITY, SloshModel, potential_flow_model


@dataclass(frozen=True)
class ModelPlantConfig:
    """The stand-in's scene. Lengths in m (world x-z for positions).

    home_x, home_z: world position of the pourer's vessel-frame origin at home.
    catcher_rim_z: world z of vessel B's rim.
    discharge_coefficient: C_d of the weir outflow. (0, 1]
    substeps: integration steps per control period (the input is interpolated linearly). [1, 100]
    arm_delay_steps: control periods by which the arm carries out each command late. [0, 100]
    slosh: the liquid's first-mode pendulum; None: potential flow for the box and fill.
    """

    vessel: VesselGeometry = field(default_factory=VesselGeometry)
    fill_depth: float = 0.1591
    home_x: float = 0.0
    home_z: float = 0.30
    catcher_rim_z: float = 0.20
    discharge_coefficient: float = 0.6
    substeps: int = 10
    gravity: float = GRAVITY
    arm_delay_steps: int = 0
    slosh: SloshModel | None = None

    def __post_init__(self) -> None:
        check_range("plant.fill_depth", self.fill_depth, 0.0, self.vessel.inner_height, "m", lo_open=True)
        check_range("plant.discharge_coefficient", self.discharge_coefficient, 0.0, 1.0, lo_open=True)
        if isinstance(self.substeps, bool) or not isinstance(self.substeps, int) or not 1 <= self.substeps <= 100:
            raise ControllerInputError(f"plant.substeps: must be an integer in [1, 100], got {self.substeps!r}")
        steps = self.arm_delay_steps
        if isinstance(steps, bool) or not isinstance(steps, int) or not 0 <= steps <= 100:
            raise ControllerInputError(f"plant.arm_delay_steps: must be an integer in [0, 100], got {steps!r}")


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
