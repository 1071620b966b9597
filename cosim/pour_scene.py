"""The pour scene: everything ``cosim pour`` needs, as frozen dataclasses that map 1:1 onto a TOML file.

``cosim scene --dump`` prints the embedded default (:class:`PourScene` with its defaults) as TOML, every field
commented with its unit and range; a user's file only needs the keys it changes. Sections: ``liquid`` (fill and how
much to pour), ``fluid`` (SPH resolution and numerics), ``controller`` (the paper's SIM, PID, CFS and catcher, from
``controllers.config``), ``coupling``, ``trajectory`` (sampling and joint-limit overrides), ``logging`` (Rerun),
``vessels`` (the pourer's and the catcher's shape, size and walls), ``placement`` (the table, the pourer's height,
where vessel B waits, the pour height), ``arms`` (the arm holding each vessel: the bundled UR10e or a user's MJCF, its
base pose, its grasp; :mod:`cosim.pour_arms`), ``robots`` (a MuJoCo scene file instead of the project's cell).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import ClassVar

from controllers.config import CATCHER, POUR, ApproachConfig, CatcherConfig, CfsConfig, PourConfig, ReturnConfig, SimConfig
from cosim.checks import check_device
from cosim.config_mapping import from_mapping, read_toml_file, to_toml
from cosim.coupling.settings import CouplingSettings, PoseFilterLimits
from cosim.errors import InputError
from cosim.fluid.config import DISCRETISATION, ArtificialViscosityScale, DensityDiffusionTerm, DensityIteration, DivergenceConstraint, FluidConfig, FreeLiquidRule, GridReset, InitialState, KernelType, ParticleShifting, PressureSolver, SurfaceDensity, TensionTreatment, ViscousTimeStep, WallModel, WallPressure
from cosim.io.recording_config import RecordingConfig
from cosim.pour_arms import ArmsSettings
from cosim.trajectory.driver_names import JointPrefix
from cosim.robots.scene_config import (
    CATCHER_HOME_X, POUR_HEIGHT, POURER_FLOOR_ABOVE_TABLE, TABLE_TOP, SceneConfig, pour_cell_config,
)
from cosim.trajectory.limits import JointLimitOverride
from cosim.trajectory.sampling import DEFAULT_SAMPLE_RATE_HZ, SAMPLE_RATE
from cosim.vessel import VesselShape, VesselSpec, default_catching_vessel, mesh_vessel_spec, seed_pouring_vessel
from declared_settings.setting import (
    Derived, argument_field, check_settings, declared, declared_fields, derived, documented, like, setting,
)


LIQUID = "liquid"
VESSEL = "vessel"
PLACEMENT = "placement"


@documented
@dataclass(frozen=True)
class LiquidSettings:
    """The liquid in the pourer and how much of it to pour."""

    fill_depth: float = setting(PourConfig.fill_depth, LIQUID, "Liquid depth in the upright pourer (the paper's A); "
                                "below the pourer's rim, which the pour checks once the vessels are built.", "m",
                                0.0, 2.0, lo_open=True)
    pour_fraction: float = setting(1.0, LIQUID, "Fraction of the liquid to pour; 1 pours until the pourer is empty.",
                                   "", 0.0, 1.0, lo_open=True)

    def __post_init__(self) -> None:
        check_settings(self, "liquid")


@dataclass(frozen=True)
class FluidSettings:
    """The liquid's settings a scene sets: every :class:`FluidConfig` setting (declared there, with its default and
    range) but those the pour derives from the robot scene (:attr:`derived_settings`,
    :func:`cosim.coupling.loop.pour_fluid_config`), and the resolution ``particles_across``."""

    # ---- discretisation
    dim: int = like(FluidConfig, "dim")
    particles_across: int = setting(32, DISCRETISATION, "Particles across the pourer's inner width B; sets the "
                                    "spacing dx = B / particles_across.", "", 8, 400)
    smoothing_ratio: float = like(FluidConfig, "smoothing_ratio")
    kernel: KernelType = like(FluidConfig, "kernel")
    wall_model: WallModel | None = like(FluidConfig, "wall_model")
    # ---- material
    rest_density: float = like(FluidConfig, "rest_density")
    kinematic_viscosity: float = like(FluidConfig, "kinematic_viscosity")
    # ---- pressure, both solvers
    pressure_solver: PressureSolver = like(FluidConfig, "pressure_solver")
    sound_speed_factor: float = like(FluidConfig, "sound_speed_factor")
    artificial_viscosity: float = like(FluidConfig, "artificial_viscosity")
    artificial_viscosity_scale: ArtificialViscosityScale = like(FluidConfig, "artificial_viscosity_scale")
    free_liquid: bool = like(FluidConfig, "free_liquid")
    free_liquid_rule: FreeLiquidRule | None = like(FluidConfig, "free_liquid_rule")
    free_surface_threshold: float = like(FluidConfig, "free_surface_threshold")
    free_artificial_viscosity: float | None = like(FluidConfig, "free_artificial_viscosity")
    artificial_viscosity_beta: float | None = like(FluidConfig, "artificial_viscosity_beta")
    initial_state: InitialState = like(FluidConfig, "initial_state")
    surface_density: SurfaceDensity = like(FluidConfig, "surface_density")
    particle_shifting: ParticleShifting = like(FluidConfig, "particle_shifting")
    shifting_coefficient: float = like(FluidConfig, "shifting_coefficient")
    # ---- WCSPH
    gamma: float = like(FluidConfig, "gamma")
    max_tension: float = like(FluidConfig, "max_tension")
    tension_treatment: TensionTreatment = like(FluidConfig, "tension_treatment")
    density_diffusion: float = like(FluidConfig, "density_diffusion")
    density_diffusion_term: DensityDiffusionTerm = like(FluidConfig, "density_diffusion_term")
    # ---- DFSPH
    density_iteration: DensityIteration = like(FluidConfig, "density_iteration")
    density_tolerance: float | None = like(FluidConfig, "density_tolerance")
    divergence_constraint: DivergenceConstraint = like(FluidConfig, "divergence_constraint")
    divergence_tolerance: float = like(FluidConfig, "divergence_tolerance")
    wall_pressure: WallPressure = like(FluidConfig, "wall_pressure")
    max_solver_iterations: int = like(FluidConfig, "max_solver_iterations")
    # ---- time stepping
    cfl: float = like(FluidConfig, "cfl")
    viscous_time_step: ViscousTimeStep = like(FluidConfig, "viscous_time_step")
    adaptive_time_step: bool = like(FluidConfig, "adaptive_time_step")
    # ---- guards
    max_density_error: float = like(FluidConfig, "max_density_error")
    max_wall_penetration: float = like(FluidConfig, "max_wall_penetration")
    min_time_step: float = like(FluidConfig, "min_time_step")
    max_energy_creation: float = like(FluidConfig, "max_energy_creation")
    # ---- runtime
    cpu_threads: int = like(FluidConfig, "cpu_threads")
    grid_reset: GridReset = like(FluidConfig, "grid_reset")

    # FluidConfig settings a scene does not set, and where the pour takes them from (the robot scene's vessels and
    # placement: cosim.coupling.loop.pour_fluid_config).
    derived_settings: ClassVar[tuple[Derived, ...]] = (
        derived(FluidConfig, "spacing", "the pourer's inner width / particles_across"),
        derived(FluidConfig, "depth_2d", "the pourer's depth"),
        derived(FluidConfig, "domain_min", "a box around both vessels and the catcher's travel, its floor just below the catcher"),
        derived(FluidConfig, "domain_max", "the same box's upper corner"),
        derived(FluidConfig, "max_expected_speed", "the larger of the stream's speed at the catcher's floor and 2 sqrt(g fill_depth)"),
        derived(FluidConfig, "gravity", "standard gravity, as the robot scene's"),
    )

    def __post_init__(self) -> None:
        check_settings(self, "fluid")

    def fluid_config(self, pourer_width: float) -> FluidConfig:
        """The solver configuration (domain and expected speed are set from the robot scene by the coupling)."""
        numerics = {name: getattr(self, name) for name, _ in declared_fields(FluidSettings) if name != "particles_across"}
        return FluidConfig(spacing=pourer_width / self.particles_across, **numerics)


@documented
@dataclass(frozen=True)
class CatcherSettings:
    """Vessel B's motion (:class:`controllers.config.CatcherConfig`, its home and travel from the scene)."""

    travel: float = setting(0.15, CATCHER, "How far vessel B may move each way along x from home (the robot scene "
                            "verifies +-0.15 m).", "m", 0.0, 0.15, lo_open=True)
    max_speed: float = like(CatcherConfig, "max_speed")
    max_accel: float = like(CatcherConfig, "max_accel")
    discharge_coefficient: float = like(CatcherConfig, "discharge_coefficient")
    filter_time: float = like(CatcherConfig, "filter_time")

    def __post_init__(self) -> None:
        check_settings(self, "controller.catcher")


# The CFS head's floor in particle spacings, by dimension (ControllerSettings.stream_particles not set): the smallest
# head (on a half-spacing grid) the liquid resolves as a flow over a crest, the weir case's discharge coefficient
# within its 5 % of Rehbock's from that head on (python -m cosim.bench.weir_head_floor [--dim 3];
# docs/outflow_validation.md has the tables). 2-D: at every resolution studied (24, 32, 48, 64 across). 3-D: at the 3-D
# pour's 32 across, in a channel as wide as the default pourer is deep (0.10 m), whose side walls cost the flow about
# a point of C_d against a channel twice as wide. Both 3 spacings: 2.5 fails in 2-D and in 3-D.
STREAM_PARTICLES = {2: 3.0, 3: 3.0}


@documented
@dataclass(frozen=True)
class ControllerSettings:
    """sim: slosh induction (Camporredondo et al. 2019, Fig. 7).
    approach: tilt toward the crest without SIM.
    cfs: constant-flow stage (Camporredondo et al. 2019, Sec. 3.2).
    returning: back upright after the pour.
    catcher: vessel B's motion.
    pose_filter: task-space limits of the vessel targets before inverse kinematics.
    """

    control_rate: float = like(PourConfig, "control_rate")
    stream_particles: float | None = setting(
        None, POUR, "The CFS liquid height over the crest is at least this many particle spacings, so that the "
        "stream is resolved (the paper holds it near the smoothing length), up to cfs.h_q_ref's limit; a partial "
        "pour's final stage holds cfs.final_head_fraction of it.", "", 0.0, 10.0,
        none_means=f"{STREAM_PARTICLES[2]:g} in 2-D, {STREAM_PARTICLES[3]:g} in 3-D (the smallest heads the weir case "
        "resolves, docs/outflow_validation.md)")
    sim: SimConfig = field(default_factory=SimConfig)
    approach: ApproachConfig = field(default_factory=ApproachConfig)
    cfs: CfsConfig = field(default_factory=CfsConfig)
    returning: ReturnConfig = field(default_factory=ReturnConfig)
    catcher: CatcherSettings = field(default_factory=CatcherSettings)
    pose_filter: PoseFilterLimits = field(default_factory=PoseFilterLimits)

    def __post_init__(self) -> None:
        check_settings(self, "controller")

    def stream_particles_in(self, dim: int) -> float:
        """``stream_particles`` as set, else its default for a ``dim``-D liquid (:data:`STREAM_PARTICLES`)."""
        return STREAM_PARTICLES[dim] if self.stream_particles is None else self.stream_particles


@documented
@dataclass(frozen=True)
class TrajectorySettings:
    """limits: per-joint overrides of the arms' limits, keyed '<arm>/<joint>' (e.g. 'pour_arm/elbow'), each with
      max_velocity (rad/s), max_acceleration (rad/s^2), max_jerk (rad/s^3), min_position, max_position (rad),
      rated_torque (N m).
    joint_prefix: per arm, the prefix of its joint names in trajectory.json and trajectory.mcap (the names its ROS 2
      driver uses, e.g. 'shoulder_pan_joint'), as the driver's tf_prefix.
    """

    sample_rate_hz: float = argument_field(SAMPLE_RATE, DEFAULT_SAMPLE_RATE_HZ)
    limits: dict[str, JointLimitOverride] = field(default_factory=dict)
    joint_prefix: JointPrefix = field(default_factory=JointPrefix)

    def __post_init__(self) -> None:
        check_settings(self, "trajectory")


@dataclass(frozen=True)
class LoggingSettings:
    """enabled: write the Rerun recording pour.rrd.
    recording: what goes into it (particle decimation, rate, colour scale).
    """

    enabled: bool = True
    recording: RecordingConfig = field(default_factory=RecordingConfig)


@documented
@dataclass(frozen=True)
class VesselSettings:
    """An open vessel standing on its floor: a box, a cylinder or the walls of a mesh file.

    mesh: a 'mesh' vessel's file: OBJ or STL, one watertight solid of the walls, in metres, its opening up (+z);
      relative to the scene file. Its size is a vessel's an arm pours from, in metres: a file outside the allowed
      sizes (one in millimetres, say) is refused with a message naming them.
    """

    shape: VesselShape = setting(VesselSpec.shape, VESSEL, "'box' or 'cylinder', an open vessel standing on its floor; "
                                 "or 'mesh', the vessel's walls from the file mesh (the sizes and the wall thickness "
                                 "then come from the mesh, docs/mesh_vessels.md).")
    # Inner sizes from a small beaker to the largest vessel the arm's 12.5 kg payload could hold.
    inner_width: float = setting(VesselSpec.inner_width, VESSEL, "Inner size along the pour direction (the vessel's x, "
                                 "toward its lip); a cylinder's inner diameter.", "m", 0.02, 0.6)
    inner_depth: float = setting(VesselSpec.inner_depth, VESSEL, "A box's inner size across the pour plane (a "
                                 "cylinder's is its diameter: this key is not used).", "m", 0.02, 0.6)
    inner_height: float = setting(VesselSpec.inner_height, VESSEL, "Inner floor to rim.", "m", 0.02, 0.6)
    # At least 1 mm: a thinner wall is not a vessel an arm can hold.
    wall_thickness: float = setting(VesselSpec.wall_thickness, VESSEL, "Floor and walls; less than the inner width "
                                    "(and a box's inner depth).", "m", 0.001, 0.05)
    # From foamed plastics to tungsten.
    wall_density: float = setting(VesselSpec.wall_density, VESSEL, "The wall material (acrylic 1180, glass 2500, steel "
                                  "7850); with the walls' volume it sets the empty vessel's mass.", "kg/m^3",
                                  100.0, 25000.0)
    mesh: str = ""
    pour_direction: float = setting(0.0, VESSEL, "A 'mesh' vessel's pour direction: the azimuth about +z, from the "
                                    "file's +x, of the wall the liquid leaves over.", "deg", -180.0, 180.0)

    @classmethod
    def of(cls, spec: VesselSpec) -> "VesselSettings":
        """The settings of the vessel ``spec``."""
        return cls(spec.shape, spec.inner_width, spec.inner_depth, spec.inner_height, spec.wall_thickness, spec.wall_density)

    def check(self, prefix: str) -> None:
        """Range checks, each message naming the field as ``<prefix>.<field>``: the declared ranges, and a wall
        thinner than the vessel is narrow; a mesh is loaded and checked (:func:`cosim.mesh_vessel.load_vessel_mesh`)."""
        check_settings(self, prefix)
        if (self.shape is VesselShape.MESH) != bool(self.mesh):
            raise InputError(f"{prefix}.mesh: a file for shape 'mesh' (and only for it), got shape {self.shape.value!r} "
                             f"and mesh {self.mesh!r}")
        if self.shape is VesselShape.MESH:
            self.spec(prefix.rsplit(".", 1)[-1], prefix)
            return
        narrowest = min(self.inner_width, self.inner_depth) if self.shape is VesselShape.BOX else self.inner_width
        if self.wall_thickness >= narrowest:
            thinnest = declared(VesselSettings, "wall_thickness").bounds.lo
            raise InputError(f"{prefix}.wall_thickness: must be in [{thinnest:g}, {narrowest:g}) m, got {self.wall_thickness:g}")

    def spec(self, name: str, prefix: str = "vessels") -> VesselSpec:
        """The :class:`VesselSpec` named ``name`` (a cylinder's depth is its diameter; a mesh's from its file, errors
        naming ``<prefix>.mesh``)."""
        if self.shape is VesselShape.MESH:
            from cosim.mesh_vessel import load_vessel_mesh  # NumPy (and trimesh): only for a mesh vessel

            mesh = load_vessel_mesh(self.mesh, self.pour_direction, f"{prefix}.mesh")
            return mesh_vessel_spec(name, mesh, self.wall_density)
        depth = self.inner_depth if self.shape is VesselShape.BOX else self.inner_width
        return VesselSpec(name, self.shape, self.inner_width, depth, self.inner_height, self.wall_thickness, self.wall_density)


@dataclass(frozen=True)
class VesselsSettings:
    """pourer: vessel A, which the pour arm tilts (default: the paper's vessel, B = L = 0.191 m, 0.10 m deep).
    catcher: vessel B, which the catch arm moves under the stream (default: 0.26 m wide, 0.14 m deep, 0.16 m high).
    """

    pourer: VesselSettings = field(default_factory=lambda: VesselSettings.of(seed_pouring_vessel()))
    catcher: VesselSettings = field(default_factory=lambda: VesselSettings.of(default_catching_vessel()))

    def __post_init__(self) -> None:
        self.pourer.check("vessels.pourer")
        self.catcher.check("vessels.catcher")


@documented
@dataclass(frozen=True)
class PlacementSettings:
    """Where the table, the pourer and the catcher stand."""

    table_height: float = setting(TABLE_TOP, PLACEMENT, "The top of the table both arms stand on (the height of their "
                                  "bases).", "m", 0.3, 1.2)
    pourer_height: float = setting(POURER_FLOOR_ABOVE_TABLE, PLACEMENT, "The pourer's inner floor above the table top "
                                   "at home.", "m", 0.1, 1.0)
    catcher_home_x: float = setting(CATCHER_HOME_X, PLACEMENT, "Where vessel B waits: its centre along the pour "
                                    "direction from the pourer's centre, at home (the catcher moves "
                                    "controller.catcher.travel each way from there).", "m", 0.0, 0.6)
    pour_height: float = setting(POUR_HEIGHT, PLACEMENT, "The pourer's lip above the catcher's rim at home (the "
                                 "controller lowers the pourer from there during the pour).", "m", 0.05, 1.0)

    def __post_init__(self) -> None:
        check_settings(self, "placement")


@dataclass(frozen=True)
class RobotSettings:
    """scene: a scene written by the project's scene builder, with its own vessels ('' = the cell of [vessels]).
    """

    scene: str = ""


DEFAULT_SCENE_NAME = "seed-pour"  # the run folders' name of the embedded default scene
_NOT_IN_NAMES = re.compile(r"[^A-Za-z0-9_-]")
# characters of a scene's name: the run folder, "<time>-<name>[-k]", and its unfinished sibling must fit the 255 bytes
# of a file name (cosim.pour_run)
MAX_NAME_LENGTH = 200


@dataclass(frozen=True)
class PourScene:
    """name: the run folder's name (recordings/<UTC time>-<name>); '' names it after the scene file (its name without
      .toml), 'seed-pour' for the embedded default scene. [letters, digits, '-', '_'; or '']
    device: 'cpu' or 'cuda[:N]'.
    liquid: fill and pour amount.
    fluid: the liquid's resolution and numerics, grouped by concern.
    controller: the pour controller.
    coupling: MuJoCo <-> liquid coupling and run length.
    trajectory: exported joint trajectories.
    logging: the Rerun recording.
    vessels: the pourer and the catcher.
    placement: where the table, the pourer and the catcher stand.
    arms: the arm holding each vessel, where it stands and how it grasps.
    robots: the MuJoCo scene.
    """

    name: str = ""
    device: str = "cpu"
    liquid: LiquidSettings = field(default_factory=LiquidSettings)
    fluid: FluidSettings = field(default_factory=FluidSettings)
    controller: ControllerSettings = field(default_factory=ControllerSettings)
    coupling: CouplingSettings = field(default_factory=CouplingSettings)
    trajectory: TrajectorySettings = field(default_factory=TrajectorySettings)
    logging: LoggingSettings = field(default_factory=LoggingSettings)
    vessels: VesselsSettings = field(default_factory=VesselsSettings)
    placement: PlacementSettings = field(default_factory=PlacementSettings)
    arms: ArmsSettings = field(default_factory=ArmsSettings)
    robots: RobotSettings = field(default_factory=RobotSettings)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or _NOT_IN_NAMES.search(self.name):
            raise InputError(f"scene.name: must be letters, digits, '-' or '_' (or '': the scene file's name), got {self.name!r}")
        if len(self.name) > MAX_NAME_LENGTH:
            raise InputError(f"scene.name: at most {MAX_NAME_LENGTH} characters (it names the run folder), got {len(self.name)}")
        check_device("scene.device", self.device)
        if self.trajectory.sample_rate_hz * self.coupling.max_duration < 1.0:  # the exported trajectory's two samples
            raise InputError(f"trajectory.sample_rate_hz: must give at least 2 samples over coupling.max_duration = "
                             f"{self.coupling.max_duration:g} s (cosim pour --duration), >= "
                             f"{1.0 / self.coupling.max_duration:.6g} Hz, or a longer run; got {self.trajectory.sample_rate_hz:g}")
        if self.robots.scene and self.cell_config() is not None:
            raise InputError("robots.scene: a scene file brings its own vessels and placement, and its arms; leave [vessels], "
                             "[placement] and [arms] at their defaults with it, or leave robots.scene out")

    def cell_config(self) -> SceneConfig | None:
        """The robot cell of :attr:`vessels`, :attr:`placement` and :attr:`arms`
        (:func:`cosim.robots.scene_config.pour_cell_config` with :meth:`cosim.pour_arms.ArmsSettings.apply`); None
        where all three are the defaults: the project's scene file (``models/scene.xml``) is that cell, ready built."""
        if self.vessels == VesselsSettings() and self.placement == PlacementSettings() and self.arms == ArmsSettings():
            return None
        p = self.placement
        return self.arms.apply(pour_cell_config(self.vessels.pourer.spec("pourer", "vessels.pourer"),
                                                self.vessels.catcher.spec("catcher", "vessels.catcher"),
                                                p.table_height, p.pourer_height, p.catcher_home_x, p.pour_height))

    @property
    def run_name(self) -> str:
        """The run folder's name: :attr:`name`, else :data:`DEFAULT_SCENE_NAME`."""
        return self.name or DEFAULT_SCENE_NAME

    def named_after(self, path: str | Path) -> "PourScene":
        """This scene, named after the file ``path`` (its stem, other characters than letters, digits, '-' and '_'
        made '_', cut to :data:`MAX_NAME_LENGTH`) unless it has a name of its own."""
        return self if self.name else replace(self, name=_NOT_IN_NAMES.sub("_", Path(path).stem)[:MAX_NAME_LENGTH])


def load_scene(path: str | Path) -> PourScene:
    """Read a scene TOML file; any problem is one InputError line naming the file and the field. Files it names by a
    relative path (``arms.*.mjcf``, ``vessels.*.mesh``, ``robots.scene``) are taken from the scene file's folder."""
    path = Path(path)
    table = read_toml_file(path, "scene file")
    for vessel in table.get("vessels", {}).values() if isinstance(table.get("vessels"), dict) else ():
        if isinstance(vessel, dict) and isinstance(vessel.get("mesh"), str) and vessel["mesh"]:
            vessel["mesh"] = os.path.abspath(path.parent / vessel["mesh"])  # relative to the scene file (an absolute path stays)
    robots = table.get("robots")
    if isinstance(robots, dict) and isinstance(robots.get("scene"), str) and robots["scene"]:
        robots["scene"] = os.path.abspath(path.parent / robots["scene"])  # as the meshes
    try:
        scene = from_mapping(PourScene, table, "scene")
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    return replace(scene, arms=scene.arms.with_folder(path.parent))


def dump_scene(scene: PourScene) -> str:
    """The scene as a documented TOML document."""
    header = (
        "cosim pour scene. Units: SI (m, s, kg, rad). Every key is optional: a file only needs what it changes.\n"
        "Run it with: cosim pour THIS_FILE.toml"
    )
    return to_toml(scene, header)
