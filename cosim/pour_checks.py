"""Every check ``cosim pour`` runs before it simulates, in the one function ``cosim scene --check`` runs too.

:func:`check_pour` refuses a scene (one :class:`InputError` line naming the field) or returns a :class:`PourPlan`:
the robot scene, the joint limits, the liquid's configuration, its particle counts, its memory and an estimate of
the run's wall time. Checked, in order: Rerun present when the recording is on; the device; the robot scene file; the
fill below the pourer's rim; the joint-limit overrides; the liquid's resolution (layers deep, particles across); the
memory of its pair tables and cell grids (:func:`cosim.fluid.memory.check_memory`); and, unless the caller accepts
long runs, the estimated wall time against :data:`LONG_RUN_S`. Nothing is allocated for the liquid and nothing is
written, so a refused scene costs seconds, not the minute a fine 3-D liquid takes to seed. The pour controller's own
checks (its PID design) need the seeded liquid's actual fill and run when the pour is built.

The estimate (:func:`estimate_wall_time`) is wall = particles x substeps x :data:`SECONDS_PER_PARTICLE_STEP`, with
substeps = ``coupling.max_duration`` / the fixed time step (:attr:`cosim.fluid.config.FluidConfig.fixed_time_step`).
It bounds the run rather than predicting it: a pour ends when the pourer is empty, usually well before
``coupling.max_duration``, and the adaptive step differs from the fixed one (docs/scene_check.md compares the
estimate with measured pours).
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib.util import find_spec
from typing import TYPE_CHECKING

from cosim.errors import InputError

if TYPE_CHECKING:
    from cosim.fluid.config import FluidConfig
    from cosim.pour_scene import PourScene
    from cosim.robots.scene import RobotScene
    from cosim.robots.scene_config import ArmRole
    from cosim.trajectory.limits import ArmLimits

# s of wall time per liquid particle per solver substep, the MuJoCo arms and the controller included (no recording):
# the default pour's wall time over its particles times substeps (summary.json's wall_time / (particles x
# sph_steps)) on a loaded 2-core CPU, rounded up (docs/scene_check.md). It includes the host's fixed share per step,
# so scenes with more particles per step are overestimated, the safe side for a gate.
SECONDS_PER_PARTICLE_STEP = 6.5e-6
LONG_RUN_S = 3600.0  # s: a longer estimate is refused unless the caller accepts it (`cosim pour --yes`)


@dataclass(frozen=True)
class PourPlan:
    """What the checks found the pour will be, before anything is built.

    particles: liquid particles (the fill volume over one particle's volume, on whole layers).
    wall_particles: the vessels' wall particles (sampled as the solver samples them).
    memory_bytes: the liquid's pair tables and cell grids (:func:`cosim.fluid.memory.liquid_bytes`).
    substeps: solver substeps over ``coupling.max_duration`` at the fixed time step.
    wall_time: s, the estimated wall time (:func:`estimate_wall_time`).
    """

    robots: RobotScene
    limits: dict[ArmRole, ArmLimits]
    fluid_base: FluidConfig
    fluid: FluidConfig
    particles: int
    wall_particles: int
    memory_bytes: int
    substeps: int
    wall_time: float

    def summary(self) -> str:
        """One line: the particle counts, the resolution and the estimate, e.g. for the progress output."""
        cfg = self.fluid
        return (f"{self.particles:,} liquid particles ({cfg.dim}-D, spacing {cfg.spacing * 1e3:.2f} mm), "
                f"{self.wall_particles:,} wall particles, {self.memory_bytes / 1e9:.2g} GB of pair tables and grids; "
                f"estimated wall time at most {_duration(self.wall_time)} ({self.substeps:,} substeps)")


def _duration(seconds: float) -> str:
    if seconds < 120.0:
        return f"{seconds:.0f} s"
    return f"{seconds / 60.0:.0f} min" if seconds < 7200.0 else f"{seconds / 3600.0:.1f} h"


def estimate_wall_time(particles: int, substeps: int) -> float:
    """s of wall time for ``particles`` liquid particles over ``substeps`` solver substeps."""
    return particles * substeps * SECONDS_PER_PARTICLE_STEP


def _joint_limits(scene: PourScene, robots: RobotScene) -> dict[ArmRole, ArmLimits]:
    from cosim.robots.scene_config import ArmRole
    from cosim.trajectory.limits import scene_limits

    roles = {r.value: r for r in ArmRole}
    overrides: dict = {}
    for name, override in scene.trajectory.limits.items():
        arm = name.split("/", 1)[0]
        if arm not in roles or "/" not in name:
            raise InputError(f"trajectory.limits.{name}: must be '<arm>/<joint>' with <arm> one of {', '.join(roles)}")
        overrides.setdefault(roles[arm], {})[name] = override
    return scene_limits(robots, overrides)


def check_pour(scene: PourScene, long_run_ok: bool = False) -> PourPlan:
    """Run every check of ``scene`` a pour needs before it is built (module docstring); InputError on the first
    that fails. ``long_run_ok``: accept an estimated wall time over :data:`LONG_RUN_S`."""
    from cosim.coupling.loop import pour_fluid_config
    from cosim.fluid.memory import check_memory, liquid_bytes
    from cosim.fluid.runtime import resolve_device
    from cosim.fluid.seeding import check_resolution, fill_layers
    from cosim.fluid.wall_sampling import sample_vessel_walls
    from cosim.robots.scene import RobotScene
    from cosim.robots.scene_config import ArmRole

    if scene.logging.enabled and find_spec("rerun") is None:
        raise InputError("logging.enabled: the Rerun recording needs rerun-sdk, which is not installed "
                         "(install it, or run without the recording: --no-log or logging.enabled = false)")
    device = resolve_device(scene.device)
    robots = RobotScene.load(scene.robots.scene or None)
    pourer = robots.arms[ArmRole.POUR].vessel
    fill = scene.liquid.fill_depth
    if not fill < pourer.inner_height:
        raise InputError(f"liquid.fill_depth: must be in (0, {pourer.inner_height:g}) m (below the pourer's rim), got {fill:g}")
    limits = _joint_limits(scene, robots)
    base = scene.fluid.fluid_config(pourer.inner_width)
    cfg = pour_fluid_config(robots, base, fill)
    check_resolution(pourer, fill, cfg)
    floor = pourer.inner_width * pourer.section_depth if cfg.dim == 2 else pourer.inner_floor_area
    particles = round(floor * fill_layers(pourer, fill, cfg.spacing) * cfg.spacing / cfg.particle_volume)
    walls = sum(len(sample_vessel_walls(robots.arms[r].vessel, cfg.spacing, cfg.support_radius, cfg.dim)[0]) for r in ArmRole)
    check_memory(cfg, particles, walls, device)
    substeps = round(scene.coupling.max_duration / cfg.fixed_time_step)
    plan = PourPlan(robots, limits, base, cfg, particles, walls, liquid_bytes(cfg, particles, walls), substeps,
                    estimate_wall_time(particles, substeps))
    if plan.wall_time > LONG_RUN_S and not long_run_ok:
        raise InputError(
            f"fluid: {particles:,} liquid particles over {substeps:,} substeps are estimated at up to "
            f"{_duration(plan.wall_time)} of wall time, over the {_duration(LONG_RUN_S)} a pour runs without --yes: pass "
            f"--yes, or make it cheaper (fewer fluid.particles_across, fluid.dim = 2, or a shorter coupling.max_duration)"
        )
    return plan
