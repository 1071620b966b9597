"""Every check ``cosim pour`` runs before it simulates, in the one function ``cosim scene --check`` runs too.

:func:`check_pour` refuses a scene (one :class:`InputError` line naming the field) or returns a :class:`PourPlan`:
the robot scene, the joint limits, the liquid's configuration, its particle counts, its memory and an estimate of
the run's wall time. Checked, in order: Rerun present when the recording is on; the device; the robot scene (the
scene file, or the cell of the scene's vessels and arms, their home postures solved); the fill below the
pourer's rim; the catcher holding what is poured; the catcher above the table; each arm's load against its rated
payload; the joint-limit overrides; the arms' reach over the pour's poses, free of collisions (:func:`check_reach`);
the liquid's resolution (layers deep, particles across); the memory of its pair tables and cell grids
(:func:`cosim.fluid.memory.check_memory`); and, unless the caller accepts long runs, the estimated wall time against
:data:`LONG_RUN_S`. Nothing is allocated for the liquid and nothing is written, so a refused scene costs seconds, not
the minute a fine 3-D liquid takes to seed. The pour controller's own checks (its PID design) need the seeded liquid's
actual fill and run when the pour is built.

The estimate (:func:`estimate_wall_time`) is wall = particles x substeps x :data:`SECONDS_PER_PARTICLE_STEP`, with
substeps = ``coupling.max_duration`` / the fixed time step (:attr:`cosim.fluid.config.FluidConfig.fixed_time_step`).
It bounds the run rather than predicting it: a pour ends when the pourer is empty, usually well before
``coupling.max_duration``, and the adaptive step differs from the fixed one (docs/scene_check.md compares the
estimate with measured pours).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from importlib.util import find_spec
from typing import TYPE_CHECKING

from cosim.errors import InputError

if TYPE_CHECKING:
    from collections.abc import Mapping

    import numpy as np

    from cosim.fluid.config import FluidConfig
    from cosim.pour_scene import PourScene
    from cosim.robots.collision import MotionChecker
    from cosim.robots.scene import RobotScene
    from cosim.robots.scene_config import ArmRole
    from cosim.trajectory.limits import ArmLimits
    from cosim.vessel import VesselSpec

# s of wall time per liquid particle per solver substep, the MuJoCo arms and the controller included (no recording):
# the default pour's wall time over its particles times substeps (summary.json's wall_time / (particles x
# sph_steps)) on a busy CPU, rounded up; the calibration run is in docs/scene_check.md. It includes the host's fixed
# share per step, so scenes with more particles per step are overestimated, the safe side for a gate.
SECONDS_PER_PARTICLE_STEP = 6.5e-6
LONG_RUN_S = 3600.0  # s: a longer estimate is refused unless the caller accepts it (`cosim pour --yes`)
# The reach check's sweep: the pourer's tilt in steps of at most this (rad, 5 deg), the catcher's travel in this many
# steps each way; each inverse-kinematics solve starts from the last, as the pour's own targets follow each other.
REACH_TILT_STEP = math.radians(5.0)
REACH_TRAVEL_STEPS = 6
# m and rad: a pose counts as reached this close (the pour's own solves converge to 1e-5 from reached poses).
REACH_TOLERANCE = 1e-4


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
        """Two lines: the particle counts, the resolution and the estimate, e.g. for the progress output; then the
        pourer's walls as the liquid sees them (:meth:`walls`)."""
        cfg = self.fluid
        return (f"{self.particles:,} liquid particles ({cfg.dim}-D, spacing {cfg.spacing * 1e3:.2f} mm), "
                f"{self.wall_particles:,} wall particles, {self.memory_bytes / 1e9:.2g} GB of pair tables and grids; "
                f"estimated wall time at most {_duration(self.wall_time)} ({self.substeps:,} substeps)\n{self.walls()}")

    def wall_report(self) -> dict[str, dict[str, str | float]]:
        """Per vessel (by its name, e.g. ``pourer``): how its walls are filled (``wall_model``,
        :func:`cosim.fluid.wall_sampling.wall_model_for`) and ``lip_outside_real_m``, how far (m) the dummy layers
        reach past its outer face, and the liquid's lip with them past the real one (0 for the vessel's own walls)."""
        from cosim.fluid.wall_sampling import numerical_wall_thickness, wall_model_for

        report = {}
        for arm in self.robots.arms.values():
            vessel = arm.vessel
            report[vessel.name] = {"wall_model": wall_model_for(vessel, self.fluid).value,
                                  "lip_outside_real_m": numerical_wall_thickness(vessel, self.fluid) - vessel.wall_thickness}
        return report

    def walls(self) -> str:
        """One line: how the pourer's walls are filled and, where the dummy layers reach past its outer face, how
        far outside the real lip the liquid's lip lies (:meth:`wall_report`)."""
        from cosim.robots.scene_config import ArmRole

        pourer = self.robots.arms[ArmRole.POUR].vessel
        report = self.wall_report()[pourer.name]
        model, past = report["wall_model"], report["lip_outside_real_m"]
        if past <= 0.0:
            return f"walls: {model}, the pourer's own {pourer.wall_thickness * 1e3:.1f} mm: the liquid leaves from its real lip"
        return (f"walls: {model}, {(pourer.wall_thickness + past) * 1e3:.1f} mm of dummy layers for the pourer's "
                f"{pourer.wall_thickness * 1e3:.1f} mm wall: the liquid's lip lies {past * 1e3:.1f} mm outside the real one "
                "(fluid.wall_model, docs/walls.md)")


def _duration(seconds: float) -> str:
    if seconds < 120.0:
        return f"{seconds:.0f} s"
    return f"{seconds / 60.0:.0f} min" if seconds < 7200.0 else f"{seconds / 3600.0:.1f} h"


def estimate_wall_time(particles: int, substeps: int) -> float:
    """s of wall time for ``particles`` liquid particles over ``substeps`` solver substeps."""
    return particles * substeps * SECONDS_PER_PARTICLE_STEP


def _joint_limits(scene: PourScene, robots: RobotScene) -> dict[ArmRole, ArmLimits]:
    """Each arm's limits: its model's, the accelerations and jerks of its ``arms`` section, then the scene's
    ``trajectory.limits`` joint by joint (a field set there wins)."""
    from dataclasses import replace

    from cosim.robots.scene_config import ArmRole
    from cosim.trajectory.limits import LIMIT_FIELDS, scene_limits

    roles = {r.value: r for r in ArmRole}
    overrides = {role: scene.arms.of(role).limit_overrides(role.value, robots.arms[role].joints) for role in ArmRole}
    for name, override in scene.trajectory.limits.items():
        arm = name.split("/", 1)[0]
        if arm not in roles or "/" not in name:
            raise InputError(f"trajectory.limits.{name}: must be '<arm>/<joint>' with <arm> one of {', '.join(roles)}")
        by_joint = overrides[roles[arm]]
        given = {f: getattr(override, f) for f in LIMIT_FIELDS if getattr(override, f) is not None}
        by_joint[name] = replace(by_joint[name], **given) if name in by_joint else override
    return scene_limits(robots, overrides, {role: scene.arms.of(role).arm_model for role in ArmRole})


def robot_scene(scene: PourScene) -> RobotScene:
    """The robot scene of ``scene``: its ``robots.scene`` file, else the project's cell around its vessels at its
    placement with its arms (the project's scene file where all are the defaults). A home posture out of reach is an
    InputError naming the setting to change (``placement``, or the arm's ``arms.*.base_pos``)."""
    from cosim.robots.scene import RobotScene

    config = scene.cell_config()
    if config is None:
        try:
            return RobotScene.load(scene.robots.scene or None)
        except InputError as exc:
            if not scene.robots.scene:
                raise
            raise InputError(f"robots.scene: {exc}") from None
    return RobotScene.from_config(config)


def _liquid_volume(vessel: VesselSpec, depth: float, dim: int) -> float:
    """m^3 of liquid ``depth`` (m) deep in the upright ``vessel`` as the ``dim``-D liquid represents it (in 2-D the
    pour-plane section times the section depth, a cylinder's too)."""
    return (vessel.inner_width * vessel.section_depth if dim == 2 else vessel.inner_floor_area) * depth


def check_vessels(scene: PourScene, robots: RobotScene) -> None:
    """The fill below the pourer's rim; the catcher holding all that is poured; in the project's cell, the catcher
    above the table and each arm's vessel, liquid and mount plate within the arm's rated payload
    (``arms.*.rated_payload``; the UR10e's :data:`cosim.robots.ur10e.UR10E_PAYLOAD_KG`)."""
    from cosim.robots.payload import LIQUID_DENSITY
    from cosim.robots.scene_config import ArmRole, MountSpec

    pourer, catcher = robots.arms[ArmRole.POUR].vessel, robots.arms[ArmRole.CATCH].vessel
    fill, dim = scene.liquid.fill_depth, scene.fluid.dim
    if not fill < pourer.inner_height:
        raise InputError(f"liquid.fill_depth: must be in (0, {pourer.inner_height:g}) m (below the pourer's rim), got {fill:g}")
    poured = scene.liquid.pour_fraction * _liquid_volume(pourer, fill, dim)
    holds = _liquid_volume(catcher, catcher.inner_height, dim)
    if poured > holds:
        raise InputError(f"vessels.catcher: holds {holds * 1e3:.2f} L up to its rim, less than the {poured * 1e3:.2f} L the pour "
                         f"pours (a larger catcher, or a smaller liquid.fill_depth or liquid.pour_fraction)")
    if scene.robots.scene:
        return  # a user's cell: its table and its arms' payload are not known here
    catcher_bottom = robots.arms[ArmRole.CATCH].home_pos[2] - catcher.wall_thickness
    table = scene.placement.table_height
    if catcher_bottom <= table:
        raise InputError(f"placement.pour_height: {scene.placement.pour_height:g} m puts the catcher's bottom "
                         f"{(table - catcher_bottom) * 1e3:.0f} mm below the table top (a smaller pour height, or a higher "
                         f"placement.pourer_height)")
    mount = MountSpec()
    plate = mount.density * (2.0 * mount.half_width) ** 2 * mount.thickness
    held = ((ArmRole.POUR, "pourer", pourer, _liquid_volume(pourer, fill, dim)), (ArmRole.CATCH, "catcher", catcher, poured))
    for role, name, vessel, liquid in held:
        load = vessel.mass + LIQUID_DENSITY * liquid + plate
        rated = scene.arms.of(role).payload_kg
        if load > rated:
            raise InputError(f"vessels.{name}: {load:.1f} kg with its liquid and mount, more than the arm's rated "
                             f"payload of {rated:g} kg (a smaller or lighter vessel, or a smaller liquid.fill_depth)")


def check_reach(robots: RobotScene, max_tilt: float, travel: float, fields: Mapping[ArmRole, str] | None = None) -> None:
    """Every pose the pour will ask of the arms reachable and free of collisions, before any simulation: the pourer
    tilted from upright to ``max_tilt`` (rad) about its bottom middle (slosh induction's pivot) and about its lip (the
    constant-flow stage's pivots lie between the two), the other vessel at home; the catcher moved ``travel`` (m) each
    way along the pour direction, the pourer upright at home. Each sweep is solved by inverse kinematics from the
    arm's home posture on, each solve starting from the last; each pose reached, and home, is posed for MuJoCo's
    collision detection (:class:`cosim.robots.collision.MotionChecker`: vessel-vessel, arm-table, arm-arm, ...). The
    first pose out of reach or in collision is an InputError naming it, and the setting it is blamed on: per arm,
    ``fields`` (default ``placement``: where the vessels stand)."""
    from cosim.robots.collision import MotionChecker
    from cosim.robots.ik import IKSettings
    from cosim.robots.planar import PlanarPose, tilt_about_pivot
    from cosim.robots.scene_config import ArmRole

    checker = MotionChecker(robots)
    _check_contact(checker, {}, "the vessels at home", fields)
    pour = robots.arms[ArmRole.POUR]
    steps = max(1, math.ceil(max_tilt / REACH_TILT_STEP))
    tilts = [max_tilt * k / steps for k in range(1, steps + 1)]
    sweeps = [
        (ArmRole.POUR, [(f"the pourer tilted {math.degrees(t):.0f} deg about its {where} (controller.cfs.max_tilt "
                         f"{math.degrees(max_tilt):.0f} deg)", tilt_about_pivot(pour.home_quat, pivot, t)) for t in tilts])
        for where, pivot in (("bottom middle", (0.0, 0.0, 0.0)), ("lip", pour.vessel.lip_local))
    ]
    for sign in (1.0, -1.0):
        offsets = [sign * travel * k / REACH_TRAVEL_STEPS for k in range(1, REACH_TRAVEL_STEPS + 1)]
        sweeps.append((ArmRole.CATCH, [(f"the catcher moved {dx:+.3f} m from its home (controller.catcher.travel "
                                        f"{travel:g} m)", PlanarPose(dx=dx)) for dx in offsets]))
    for role, poses in sweeps:
        arm = robots.arms[role]
        ik = robots.ik(role, IKSettings(position_tolerance=REACH_TOLERANCE, rotation_tolerance=REACH_TOLERANCE))
        field = (fields or {}).get(role, "placement")
        q = arm.home_q
        for label, pose in poses:
            pos, quat = robots.vessel_target(role, pose)
            result = ik.solve(pos, quat, q)
            if not result.converged:
                raise InputError(
                    f"{field}: {label} is out of {role.value}'s reach (the closest pose "
                    f"found is {result.position_error * 1e3:.1f} mm and {math.degrees(result.rotation_error):.2f} deg "
                    f"away); place the vessels nearer the arms (placement.*) or the arms nearer the vessels "
                    f"(arms.*.base_pos), or ask less of them"
                )
            q = result.q
            _check_contact(checker, {role: q}, label, fields)


def _check_contact(
    checker: MotionChecker, configuration: dict[ArmRole, np.ndarray], label: str, fields: Mapping[ArmRole, str] | None
) -> None:
    """InputError naming ``label`` where the arms at ``configuration`` (role -> joint angles, rad; the other arm at
    home) touch anything (:meth:`cosim.robots.collision.MotionChecker.contact_at`), blamed on the ``fields`` entry of an
    arm whose part touches, where it is not ``placement``, else on ``placement``."""
    hit = checker.contact_at(configuration)
    if hit is not None:
        touching = [f for role, f in (fields or {}).items()
                    if any(body.startswith(f"{role.value}/") for body in (hit.body1, hit.body2))]
        field = next((f for f in touching if f != "placement"), "placement")
        raise InputError(
            f"{field}: {label}: {hit.geom1} ({hit.body1}) touches {hit.geom2} ({hit.body2}) ({hit.pair}, "
            f"{-hit.distance * 1e3:.1f} mm deep); place the vessels (placement.*) or the arms (arms.*.base_pos) "
            f"elsewhere, seed their home postures elsewhere (arms.*.home_seed), or ask less of the arms"
        )


def check_pour(scene: PourScene, long_run_ok: bool = False) -> PourPlan:
    """Run every check of ``scene`` a pour needs before it is built (module docstring); InputError on the first
    that fails. ``long_run_ok``: accept an estimated wall time over :data:`LONG_RUN_S`."""
    from cosim.coupling.loop import pour_fluid_config
    from cosim.fluid.memory import check_memory, liquid_bytes
    from cosim.fluid.runtime import resolve_device
    from cosim.fluid.seeding import check_resolution, fill_layers
    from cosim.fluid.wall_sampling import sample_vessel_walls
    from cosim.robots.scene_config import ArmRole

    if scene.logging.enabled and find_spec("rerun") is None:
        raise InputError("logging.enabled: the Rerun recording needs rerun-sdk, which is not installed "
                         "(install it, or run without the recording: --no-log or logging.enabled = false)")
    device = resolve_device(scene.device)
    robots = robot_scene(scene)
    pourer = robots.arms[ArmRole.POUR].vessel
    fill = scene.liquid.fill_depth
    check_vessels(scene, robots)
    limits = _joint_limits(scene, robots)
    check_reach(robots, scene.controller.cfs.max_tilt, scene.controller.catcher.travel, scene.arms.reach_fields())
    base = scene.fluid.fluid_config(pourer.inner_width)
    cfg = pour_fluid_config(robots, base, fill)
    check_resolution(pourer, fill, cfg)
    seeded_depth = fill_layers(pourer, fill, cfg.spacing) * cfg.spacing
    particles = round(_liquid_volume(pourer, seeded_depth, cfg.dim) / cfg.particle_volume)
    walls = sum(len(sample_vessel_walls(robots.arms[r].vessel, cfg)[0]) for r in ArmRole)
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
