"""Collision check of a planned motion of both arms, before it is used.

A motion is a time series of joint configurations per arm (rad, the arms' joint order). Each configuration is
posed on a private copy of the model and data (the live simulation is never touched) and MuJoCo's collision detection
(``mj_kinematics`` + ``mj_collision``) runs on it; consecutive samples are subdivided so that no joint moves more than ``max_joint_step`` between checks.
Pairs the scene excludes (neighbouring links, a vessel with its own mount and flange link) never produce contacts;
every other contact closer than ``clearance`` is a collision: arm-arm, arm-table, vessel-vessel, arm-vessel, ...
The first one in time is reported.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from enum import Enum

import mujoco
import numpy as np

from cosim.errors import InputError
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmRole
from declared_settings.setting import argument

# Default largest joint change between two checked configurations, rad (1 deg: with links up to ~1.3 m from the
# base, points move at most ~23 mm between checks, below the smallest collision geom radius of 43 mm).
DEFAULT_MAX_JOINT_STEP = np.radians(1.0)
COLLISION = "collision check"
CLEARANCE = argument(COLLISION, "Added to every geom's margin: parts closer than this count as touching.", "m", 0.0, 0.2)
MAX_JOINT_STEP = argument(COLLISION, "Largest joint change between two checked configurations.", "rad", 0.0, 0.5,
                          lo_open=True)


class PartKind(Enum):
    """What a colliding body is."""

    ARM = "arm"
    VESSEL = "vessel"  # a vessel, its mount plate or its rigid liquid payload
    TABLE = "table"
    FLOOR = "floor"
    OTHER = "other"


@dataclass(frozen=True)
class Collision:
    """The first contact found along a motion.

    time: s, on the motion's time axis (interpolated between samples when found on a subdivision).
    geom1, geom2, body1, body2: names of the touching geoms and their bodies.
    kind1, kind2: :class:`PartKind` of each side; pair: e.g. ``"arm-table"``.
    distance: m, signed distance between the geoms (negative: penetration).
    """

    time: float
    geom1: str
    geom2: str
    body1: str
    body2: str
    kind1: PartKind
    kind2: PartKind
    distance: float

    @property
    def pair(self) -> str:
        return "-".join(sorted((self.kind1.value, self.kind2.value)))

    def describe(self) -> str:
        return (
            f"{self.pair} collision at t={self.time:.3f} s: {self.geom1} ({self.body1}) touches {self.geom2} "
            f"({self.body2}), distance {self.distance * 1000:.1f} mm"
        )


class MotionChecker:
    """Collision checks on a private model/data copy of ``scene`` (``clearance``: :data:`CLEARANCE`,
    ``max_joint_step``: :data:`MAX_JOINT_STEP`)."""

    def __init__(self, scene: RobotScene, clearance: float = 0.0, max_joint_step: float = DEFAULT_MAX_JOINT_STEP):
        self.scene = scene
        self.clearance = CLEARANCE.check("collision.clearance", clearance)
        self.max_joint_step = MAX_JOINT_STEP.check("collision.max_joint_step", max_joint_step)
        self.model = self._model_with_margin(scene, self.clearance)
        self.data = mujoco.MjData(self.model)
        self._kinds = self._classify_bodies()

    @staticmethod
    def _model_with_margin(scene: RobotScene, clearance: float) -> mujoco.MjModel:
        """A private model whose geoms generate contacts ``clearance`` m early.

        The margin has to be set before compiling: MuJoCo's broad phase uses bounds computed at compile time.
        """
        if clearance == 0.0:
            return copy.copy(scene.model)
        if scene.spec is None:
            raise InputError("collision.clearance: a positive clearance needs a scene loaded from its MjSpec")
        spec = scene.spec.copy()
        for geom in spec.geoms:
            geom.margin = geom.margin + clearance
        return spec.compile()

    def _classify_bodies(self) -> list[PartKind]:
        """Kind of every body: vessel parts (vessel, its mount, bodies under the vessel), the rest of each arm's tree."""
        m = self.model
        kinds = [PartKind.OTHER] * m.nbody
        vessel_parts: set[int] = set()
        for arm in self.scene.arms.values():
            vessel_parts |= {arm.vessel_body, int(m.body_parentid[arm.vessel_body])}
            arm_root = m.body_rootid[arm.flange_body]
            for b in range(1, m.nbody):
                if m.body_rootid[b] == arm_root:
                    kinds[b] = PartKind.ARM
        for b in range(1, m.nbody):  # bodies are numbered parents first
            if b in vessel_parts or m.body_parentid[b] in vessel_parts:
                vessel_parts.add(b)
                kinds[b] = PartKind.VESSEL
        return kinds

    def _geom_kind(self, geom: int) -> PartKind:
        body = self.model.geom_bodyid[geom]
        if body == 0:
            name = self.model.geom(geom).name
            return PartKind.TABLE if name == "table" else PartKind.FLOOR if name == "floor" else PartKind.OTHER
        return self._kinds[body]

    def contact_at(self, configuration: dict[ArmRole, np.ndarray], time: float = 0.0) -> Collision | None:
        """The closest contact (or None) with the arms at ``configuration`` (role -> q (n,) rad; others at home)."""
        m, d = self.model, self.data
        d.qpos[:] = m.key_qpos[self.scene.home_key]
        for role, q in configuration.items():
            d.qpos[self.scene.arms[role].qpos_adr] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        hits = [c for c in d.contact[: d.ncon] if c.dist < self.clearance]
        if not hits:
            return None
        c = min(hits, key=lambda h: h.dist)
        return Collision(
            time=time,
            geom1=m.geom(c.geom1).name or f"geom {c.geom1}",
            geom2=m.geom(c.geom2).name or f"geom {c.geom2}",
            body1=m.body(m.geom_bodyid[c.geom1]).name,
            body2=m.body(m.geom_bodyid[c.geom2]).name,
            kind1=self._geom_kind(c.geom1),
            kind2=self._geom_kind(c.geom2),
            distance=float(c.dist),
        )

    def check_motion(self, times: np.ndarray, motion: dict[ArmRole, np.ndarray]) -> Collision | None:
        """First collision along ``motion`` (role -> (N, n) joint angles, rad) sampled at ``times`` (N,) s, or None.

        Arms missing from ``motion`` stay at home.
        """
        times = np.asarray(times, dtype=float)
        if times.ndim != 1 or times.size == 0 or np.any(np.diff(times) <= 0.0) or not np.all(np.isfinite(times)):
            raise InputError("motion.times: must be a non-empty, finite, strictly increasing 1-D array of seconds")
        paths = {}
        for role, q in motion.items():
            q = np.asarray(q, dtype=float)
            n = len(self.scene.arms[role].joints)
            if q.shape != (times.size, n) or not np.all(np.isfinite(q)):
                raise InputError(f"motion[{role.value}]: must be a finite ({times.size}, {n}) array of joint angles, got {q.shape}")
            paths[role] = q
        for i in range(times.size):
            if i == 0:
                samples = [(times[0], {role: q[0] for role, q in paths.items()})]
            else:
                largest = max((float(np.max(np.abs(q[i] - q[i - 1]))) for q in paths.values()), default=0.0)
                steps = max(1, int(np.ceil(largest / self.max_joint_step)))
                samples = [
                    (
                        times[i - 1] + (k / steps) * (times[i] - times[i - 1]),
                        {role: q[i - 1] + (k / steps) * (q[i] - q[i - 1]) for role, q in paths.items()},
                    )
                    for k in range(1, steps + 1)
                ]
            for t, config in samples:
                hit = self.contact_at(config, float(t))
                if hit is not None:
                    return hit
        return None
