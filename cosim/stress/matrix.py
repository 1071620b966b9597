"""The stability matrix: axes, the frozen per-configuration record with a stable id, and filtering.

A configuration is one point of the cartesian product of :data:`MOTIONS` x :data:`FILLS` x :data:`RESOLUTIONS`
(per dimension) x :data:`CFL_FACTORS` x :data:`DIMS` x pressure solvers (every member of
:class:`cosim.fluid.config.PressureSolver`). Its ``id`` is a hash of its fields' canonical text, the same in every
process and Python version, so result files can be resumed by id.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass
from enum import Enum

from cosim.fluid.config import GRAVITY, FluidConfig, PressureSolver
from cosim.fluid.seeding import fill_layers
from cosim.frames import Pose
from cosim.validation.common import case_fluid_config
from cosim.validation.scripted import FALL_HEIGHT, PoseScript, domain_around, shake_sideways, tilt_about_lip
from cosim.validation.slosh import eq17_frequency
from cosim.vessel import VesselSpec, seed_pouring_vessel

DURATION = 0.6  # s simulated per configuration: the whole matrix's time budget (docs/tuning.md)
TILT_ANGLE = math.pi / 2  # rad, a tilt stops (and is held) at 90 deg
CARRY_TIME = 0.4  # s, a carry accelerates and stops within this time, then the vessel is held
# Bound on the linear slosh response of a carry, in units of the quasi-static surface rise (B/2) a_max / g. By
# Duhamel's integral an undamped oscillator driven by a(t) (a(0-) = 0) stays within (max|a| + total variation of a)
# / omega^2; the carry's acceleration a_max cos(pi t / T) jumps by a_max at the start and at the stop and sweeps 2
# a_max between, so max|a| + TV = 5 a_max.
SLOSH_AMPLIFICATION = 5.0


class Motion(Enum):
    """Scripted vessel motion; its ``level`` is a tilt rate (rad/s), a shake amplitude (m) or a carry peak
    speed (m/s)."""

    TILT = "tilt"  # rotation about the pour lip at a constant rate up to TILT_ANGLE, then held
    SHAKE = "shake"  # x = level sin(omega1 t) at the first sloshing mode (linear theory, see shake_omega)
    CARRY = "carry"  # x = D/2 (1 - cos(pi t / CARRY_TIME)), peak speed = level, then held


MOTIONS: tuple[tuple[Motion, float], ...] = (
    (Motion.TILT, 1.0),
    (Motion.TILT, 5.0),
    (Motion.SHAKE, 0.005),
    (Motion.SHAKE, 0.02),
    (Motion.CARRY, 0.1),
    (Motion.CARRY, 0.3),
    (Motion.CARRY, 1.0),
)
FILLS = (0.10, 0.50, 0.95)  # fraction of the vessel's inner height
# particles across the inner width: 32 resolves the 10 % fill in 3 layers (coarser ones are refused at set-up, which
# the matrix shows); 3-D from 8 (4 across the depth, the least the seeding accepts), coarse only, for the budget
RESOLUTIONS = {2: (12, 18, 24, 32), 3: (8, 10)}
CFL_FACTORS = (1.0, 2.0)  # x the default Courant number (FluidConfig.cfl)
DIMS = (2, 3)
DEFAULT_CFL = FluidConfig().cfl


def solvers() -> tuple[str, ...]:
    return tuple(s.value for s in PressureSolver)


@dataclass(frozen=True)
class StressConfig:
    """One configuration. motion/level: see :class:`Motion`. fill: fraction of the inner height (0, 1).
    across: particles across the inner width (sets dx). cfl_factor: x the default Courant number. dim: 2 or 3.
    solver: a :class:`PressureSolver` value."""

    motion: Motion
    level: float
    fill: float
    across: int
    cfl_factor: float
    dim: int
    solver: str

    @property
    def key(self) -> str:
        """Canonical text of the fields (what the id hashes)."""
        return (f"motion={self.motion.value};level={self.level:g};fill={self.fill:g};across={self.across};"
                f"cfl={self.cfl_factor:g};dim={self.dim};solver={self.solver}")

    @property
    def id(self) -> str:
        return hashlib.sha1(self.key.encode()).hexdigest()[:12]

    @property
    def label(self) -> str:
        unit = {Motion.TILT: "rad/s", Motion.SHAKE: "m", Motion.CARRY: "m/s"}[self.motion]
        return (f"{self.motion.value} {self.level:g} {unit}, fill {100 * self.fill:.0f}%, {self.across} across, "
                f"CFL x{self.cfl_factor:g}, {self.dim}-D, {self.solver}")

    # ---- what it simulates ----------------------------------------------------------------------------------
    def spec(self) -> VesselSpec:
        return seed_pouring_vessel()

    @property
    def fill_depth(self) -> float:
        """m."""
        return self.fill * self.spec().inner_height

    @property
    def spacing(self) -> float:
        """m, dx."""
        return self.spec().inner_width / self.across

    @property
    def layers(self) -> int:
        """Particle layers the fill is seeded with (the liquid's resolution in depth)."""
        return fill_layers(self.spec(), self.fill_depth, self.spacing)

    @property
    def shake_omega(self) -> float:
        """rad/s, first sloshing mode of this fill (:func:`cosim.validation.slosh.eq17_frequency`)."""
        return 2.0 * math.pi * eq17_frequency(self.spec().inner_width, self.fill_depth)

    @property
    def carry_distance(self) -> float:
        """m a carry travels (its peak speed is pi D / (2 CARRY_TIME))."""
        return 2.0 * self.level * CARRY_TIME / math.pi

    @property
    def excursion(self) -> float:
        """m, largest sideways displacement of the vessel."""
        return {Motion.TILT: 0.0, Motion.SHAKE: self.level, Motion.CARRY: self.carry_distance}[self.motion]

    def pose_script(self) -> PoseScript:
        spec = self.spec()
        if self.motion is Motion.TILT:
            return tilt_about_lip(spec, self.level, TILT_ANGLE)
        if self.motion is Motion.SHAKE:
            return shake_sideways(self.level, self.shake_omega)
        return _carry(self.carry_distance)

    @property
    def can_spill(self) -> bool:
        """Whether the motion may bring liquid over the rim. Tilts and resonant shakes are taken to always spill;
        a carry cannot when the fill plus SLOSH_AMPLIFICATION x the quasi-static rise (B/2) a_max / g stays below
        the rim (then any particle out of the vessel is a leak)."""
        if self.motion is not Motion.CARRY:
            return True
        spec = self.spec()
        a_max = 0.5 * self.carry_distance * (math.pi / CARRY_TIME) ** 2
        rise = SLOSH_AMPLIFICATION * 0.5 * spec.inner_width * a_max / GRAVITY
        return self.fill_depth + rise >= spec.inner_height

    def fluid_config(self) -> FluidConfig:
        """The validation cases' fluid set-up (project defaults, c0 from the liquid height including the fall),
        with this Courant number and pressure solver."""
        spec = self.spec()
        # the solver goes in at construction: the settings left unset resolve per solver (artificial_viscosity)
        base = case_fluid_config(self.dim, self.spacing, max(self.fill_depth, FALL_HEIGHT), spec.section_depth,
                                 *domain_around(spec, self.excursion), solver=PressureSolver(self.solver))
        return dataclasses.replace(base, cfl=DEFAULT_CFL * self.cfl_factor)


def _carry(distance: float) -> PoseScript:
    def pose_at(t: float) -> Pose:
        s = min(t, CARRY_TIME) / CARRY_TIME
        return Pose((0.5 * distance * (1.0 - math.cos(math.pi * s)), 0.0, 0.0))

    return pose_at


def build_matrix() -> list[StressConfig]:
    """Every configuration of the axes, in a fixed order (cheap 2-D first)."""
    return [
        StressConfig(motion, level, fill, across, cfl, dim, solver)
        for solver in solvers()
        for dim in DIMS
        for across in RESOLUTIONS[dim]
        for cfl in CFL_FACTORS
        for motion, level in MOTIONS
        for fill in FILLS
    ]


QUICK = (  # a few cheap, coarse configurations of each motion (tests, smoke runs)
    (Motion.TILT, 5.0, 0.5, 12, 2.0, 2),
    (Motion.SHAKE, 0.02, 0.95, 12, 1.0, 2),
    (Motion.CARRY, 0.3, 0.10, 12, 1.0, 2),
)


def quick_matrix() -> list[StressConfig]:
    return [StressConfig(m, lv, f, a, c, d, PressureSolver.WCSPH.value) for m, lv, f, a, c, d in QUICK]
