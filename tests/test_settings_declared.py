"""The controller's, the coupling's, the scene's, the robots', the trajectories' and the validation cases' settings
and the building blocks' arguments are declared once (declared_settings.setting): each range is enforced from that declaration, one step outside each bound is refused with
one line naming the field and the range, the bound itself is accepted, each class's reference lists every setting,
and ``cosim scene --dump`` shows each scene setting with the allowed values from the same declaration."""

from __future__ import annotations

import dataclasses
import functools
import re
import types

import numpy as np
import pytest

from controllers.config import ApproachConfig, CatcherConfig, CfsConfig, PourConfig, ReturnConfig, SimConfig
from controllers.geometry import VesselGeometry
from controllers.model_plant import ModelPlantConfig
from controllers.pid_spec import PidDesignSpec
from controllers.slosh import SloshModel
from controllers.motion import (
    BANDWIDTH, MAX_ACCEL, MAX_JERK, MAX_RATE, STAGES, STOP_ACCEL, TIME_STEP, CriticallyDampedSmoother, JerkLimitedMove,
    RateLimitedTracker,
)
from cosim.cli.main import main
from cosim.coupling import tracking_filter
from cosim.coupling.settings import CouplingSettings, PoseFilterLimits
from cosim.coupling.tracking_filter import TrackingFilter
from cosim.errors import InputError
from cosim.io.recording import PARTICLE_RADIUS, PourRecorder
from cosim.io.recording_config import RecordingConfig
from cosim.pour_arms import ArmSettings, ArmsSettings
from cosim.robots.collision import CLEARANCE, MAX_JOINT_STEP, MotionChecker
from cosim.robots.ik import IKSettings
from cosim.robots.scene import RobotScene
from cosim.robots.scene_config import ArmModel, ArmPlacement, MountSpec, TableSpec, default_scene_config
from cosim.pour_scene import (
    CatcherSettings, ControllerSettings, LiquidSettings, PlacementSettings, PourScene, TrajectorySettings,
    VesselSettings, VesselsSettings,
)
from cosim.sweep.spec import POURS, SEED, parse_sweep
from cosim.trajectory.generator import GeneratorSettings
from cosim.trajectory.limits import JointLimits
from cosim.trajectory.pour_motion import PourMotionSpec
from cosim.trajectory.recorder import TrajectoryRecorder
from cosim.trajectory.sampling import SAMPLE_RATE
from cosim.vessel import VesselSpec
from cosim.validation import coupling_static, dam_break, free_fall, hydrostatic, moving_vessel, slosh, slosh_plant, weir
from declared_settings.setting import REQUIRED, declared, declared_fields
from tests.support.cli_refusal import refusal
from tests.support.setting_bounds import inside, outside


def _pour(**values) -> PourConfig:
    return PourConfig(catcher=CatcherConfig(home_x=0.0), **values)


def _pourer(**values) -> VesselsSettings:
    return VesselsSettings(pourer=VesselSettings(**values))


JOINTS = tuple(f"joint_{i}" for i in range(1, 7))
# a user's arm as a scene file gives it: what it must give, with arbitrary values in range (its file is not read)
USER_ARM = dict(mjcf="arm.xml", joints=JOINTS, flange_site="flange", max_velocity=(1.0,) * 6, rated_payload=10.0)


def _arm_model(**values) -> ArmModel:
    given = {k: v for k, v in USER_ARM.items() if k != "rated_payload"}
    return ArmModel(**{**given, **values}, label="arms.pour")


def _arm_settings(**values) -> ArmsSettings:
    return ArmsSettings(pour=ArmSettings(**{**USER_ARM, **values}))


def _joint(**values) -> JointLimits:
    given = dict(max_velocity=1.0, max_acceleration=1.0, max_jerk=1.0, min_position=-1.0, max_position=1.0)
    return JointLimits(name="arm/joint", **{**given, **values})


# class, how to build it with some of its settings given, the prefix its messages name the fields with
CLASSES = [
    (SimConfig, SimConfig, "sim."),
    (PidDesignSpec, PidDesignSpec, "pid."),
    (SloshModel, lambda **v: SloshModel(**{"l1": 0.1, "hinge_height": 0.1, **v}), "slosh."),
    (ApproachConfig, ApproachConfig, "approach."),
    (CfsConfig, CfsConfig, "cfs."),
    (ReturnConfig, ReturnConfig, "returning."),
    (CatcherConfig, lambda **v: CatcherConfig(**{"home_x": 0.0, **v}), "catcher."),
    (PourConfig, _pour, "pour."),
    (ModelPlantConfig, ModelPlantConfig, "plant."),
    (VesselGeometry, VesselGeometry, "vessel."),
    (VesselSpec, VesselSpec, "vessel[pourer]."),
    (CouplingSettings, CouplingSettings, "coupling."),
    (PoseFilterLimits, PoseFilterLimits, "pose_filter."),
    (LiquidSettings, LiquidSettings, "liquid."),
    (CatcherSettings, CatcherSettings, "controller.catcher."),
    (ControllerSettings, ControllerSettings, "controller."),
    (TrajectorySettings, TrajectorySettings, "trajectory."),
    (PlacementSettings, PlacementSettings, "placement."),
    (VesselSettings, _pourer, "vessels.pourer."),
    (RecordingConfig, RecordingConfig, "recording."),
    (JointLimits, _joint, "limits.arm/joint."),
    (ArmModel, _arm_model, "arms.pour."),
    (ArmSettings, _arm_settings, "arms.pour."),
    (ArmPlacement, lambda **v: dataclasses.replace(default_scene_config().pour, **v), "pour_arm."),
    (TableSpec, TableSpec, "table."),
    (MountSpec, MountSpec, "mount."),
    (IKSettings, IKSettings, "ik."),
    (GeneratorSettings, GeneratorSettings, "trajectory."),
    (PourMotionSpec, PourMotionSpec, "pour."),
    # the validation cases name their parameters as their command-line options, with no prefix
    (coupling_static.Params, coupling_static.Params, ""),
    (dam_break.Params, dam_break.Params, ""),
    (free_fall.Params, free_fall.Params, ""),
    (hydrostatic.Params, hydrostatic.Params, ""),
    (moving_vessel.Params, moving_vessel.Params, ""),
    (slosh.Params, slosh.Params, ""),
    (slosh_plant.Params, slosh_plant.Params, ""),
    (weir.Params, lambda **v: weir.Params(**{"spacing": 0.001, **v}), ""),  # fine enough for the smallest head
]


def _part(built, cls):
    """The instance of ``cls`` in what a build returned (a scene section holds the vessel or the arm)."""
    return built.pourer if cls is VesselSettings else built.pour if cls is ArmSettings else built


def _owner(build, cls):
    """The object whose attributes a named bound reads (and whose joints a per-joint setting counts): the class as
    built with its defaults."""
    return _part(build(), cls)


def _given(spec, value, owner):
    """``value`` as the setting is given: itself, or for a per-joint setting (or a vector bounded component by
    component) at the first joint (component), the others inside."""
    if spec.kind not in EACH:
        return value
    count = owner.joint_count if spec.kind == "per_joint" else spec.length
    return (value,) + (inside(spec, owner)[0],) * (count - 1)


def _field(spec, name: str) -> str:
    return f"{name}[0]" if spec.kind in EACH else name


EACH = ("per_joint", "components")  # the kinds whose every number is bounded
BOUNDED = [(cls, build, prefix, name, spec) for cls, build, prefix in CLASSES for name, spec in declared_fields(cls)
           if spec.bounds is not None and spec.kind in ("float", "int") + EACH]
IDS = [f"{prefix or cls.__module__.rsplit('.', 1)[-1] + '.'}{name}" for cls, _, prefix, name, _ in BOUNDED]


@pytest.mark.parametrize("cls, build, prefix, name, spec", BOUNDED, ids=IDS)
def test_each_bound_is_refused_one_step_outside_with_one_line_naming_the_field_and_the_range(cls, build, prefix, name, spec):
    owner = _owner(build, cls)
    unit = f" {spec.unit}" if spec.unit else ""
    for value in outside(spec, owner):
        with pytest.raises(InputError) as err:
            build(**{name: _given(spec, value, owner)})
        message = str(err.value)
        assert message.startswith(f"{prefix}{_field(spec, name)}: must be in {spec.bounds.of(owner).text()}{unit}, got "), message
        assert "\n" not in message


@pytest.mark.parametrize("cls, build, prefix, name, spec", BOUNDED, ids=IDS)
def test_each_bound_itself_is_accepted(cls, build, prefix, name, spec):
    owner = _owner(build, cls)
    for value in inside(spec, owner):
        try:
            built = build(**{name: _given(spec, value, owner)})
        except InputError as exc:  # a check across settings may refuse the combination, never this range
            assert not str(exc).startswith(f"{prefix}{_field(spec, name)}: must be in "), exc
            continue
        assert getattr(_part(built, cls), name) == _given(spec, value, owner)


CHOICES = [(cls, build, prefix, name) for cls, build, prefix in CLASSES for name, spec in declared_fields(cls)
           if spec.kind in ("choice", "bool")]


@pytest.mark.parametrize("cls, build, prefix, name", CHOICES, ids=[f"{p}{n}" for _, _, p, n in CHOICES])
def test_choices_and_switches_are_enforced_from_their_declarations(cls, build, prefix, name):
    allowed = "one of " if declared(cls, name).kind == "choice" else "true or false"
    with pytest.raises(InputError, match=f"^{re.escape(prefix + name)}: must be {allowed}"):
        build(**{name: "no-such-choice"})


@pytest.mark.parametrize("cls", [c for c, _, _ in CLASSES], ids=[c.__module__ + "." + c.__name__ for c, _, _ in CLASSES])
def test_each_class_documents_every_setting_from_its_declaration(cls):
    for name, spec in declared_fields(cls):
        assert spec.meaning.strip().endswith("."), name
        assert f"{name}: {spec.meaning} Allowed: {spec.allowed()}." in cls.__doc__, name


def test_a_setting_with_no_default_is_required():
    assert dataclasses.fields(CatcherConfig)[0].default is REQUIRED
    with pytest.raises(TypeError, match="home_x"):
        CatcherConfig()


def test_a_setting_with_a_default_and_a_meaning_of_none_takes_none_in_code():
    assert declared(PidDesignSpec, "noise_frequency").optional
    assert PidDesignSpec().noise_frequency > 0.0 and PidDesignSpec(noise_frequency=None).noise_frequency is None


def test_the_scene_takes_the_controllers_declarations_and_defaults():
    for name in ("max_speed", "max_accel", "discharge_coefficient", "filter_time"):
        assert declared(CatcherSettings, name) == declared(CatcherConfig, name), name
        assert getattr(CatcherSettings(), name) == getattr(CatcherConfig(home_x=0.0), name), name
    assert declared(ControllerSettings, "control_rate") == declared(PourConfig, "control_rate")
    assert ControllerSettings().control_rate == _pour().control_rate
    assert LiquidSettings().fill_depth == _pour().fill_depth == coupling_static.Params().fill


def test_the_scene_and_the_recorder_take_the_sample_rate_from_one_declaration():
    assert declared(TrajectorySettings, "sample_rate_hz") is SAMPLE_RATE


def test_the_scene_keeps_each_sections_own_defaults():
    scene = PourScene()
    assert scene.coupling == CouplingSettings() and scene.logging.recording == RecordingConfig()


def test_the_scenes_arm_sections_take_the_placements_declarations():
    for name in ("base_pos", "base_yaw", "home_seed", "grasp_pos"):
        placement, section = declared(ArmPlacement, name), declared(ArmSettings, name)
        assert dataclasses.replace(section, optional=False, none_means="") == dataclasses.replace(
            placement, optional=False, none_means=""), name


# the scene's tables of declared settings, as a scene file names them
SCENE_TABLES = [("liquid", LiquidSettings, "liquid."), ("controller", ControllerSettings, "controller."),
                ("controller.sim", SimConfig, "sim."), ("controller.sim.pid", PidDesignSpec, "pid."),
                ("controller.approach", ApproachConfig, "approach."),
                ("controller.cfs", CfsConfig, "cfs."), ("controller.returning", ReturnConfig, "returning."),
                ("controller.catcher", CatcherSettings, "controller.catcher."),
                ("controller.pose_filter", PoseFilterLimits, "pose_filter."), ("coupling", CouplingSettings, "coupling."),
                ("trajectory", TrajectorySettings, "trajectory."), ("placement", PlacementSettings, "placement."),
                ("vessels.pourer", VesselSettings, "vessels.pourer."), ("logging.recording", RecordingConfig, "recording.")]
BAD_SCENE_VALUES = [(table, prefix, name, value) for table, cls, prefix in SCENE_TABLES
                    for name, spec in declared_fields(cls) if spec.bounds is not None and spec.kind in ("float", "int")
                    for value in outside(spec, cls() if cls is not VesselSettings else VesselSettings())]


@pytest.mark.parametrize("table, prefix, name, value", BAD_SCENE_VALUES,
                         ids=[f"{t}.{n}={v:g}" for t, _, n, v in BAD_SCENE_VALUES])
def test_a_scene_value_outside_its_range_is_refused_with_one_line_and_exit_2(tmp_path, capsys, table, prefix, name, value):
    path = tmp_path / "bad.toml"
    path.write_text(f"[{table}]\n{name} = {value!r}\n")
    message = refusal(capsys, ["scene", "--check", str(path)], "scene")
    assert f"{prefix}{name}: must be in " in message, message


def test_scene_dump_shows_each_scene_setting_with_its_allowed_values(capsys):
    assert main(["scene", "--dump"]) == 0
    text = capsys.readouterr().out
    for table, cls, _ in SCENE_TABLES + [("arms.pour", ArmSettings, ""), ("arms.catch", ArmSettings, "")]:
        body = text.split(f"\n[{table}]\n", 1)[1].split("\n[", 1)[0]
        for name, spec in declared_fields(cls):
            lines = [line for line in body.splitlines() if line.startswith((f"{name} = ", f"# {name} = "))]
            assert len(lines) == 1 and lines[0].endswith(f"# {spec.meaning} Allowed: {spec.allowed()}."), (table, name)


@functools.cache
def _robot_scene() -> RobotScene:
    return RobotScene.load()


def _recorder(radius: float, folder) -> None:
    with PourRecorder(folder / "r.rrd", _robot_scene().model, particle_radius=radius):
        pass


def _move(**values) -> JerkLimitedMove:
    return JerkLimitedMove(**{"position": 0.0, "velocity": 0.0, "target": 1.0, "max_rate": 1.0, "max_accel": 2.0,
                              "max_jerk": 10.0, **values})


ONES = np.ones(2)
# the declared arguments of the building blocks: declaration, how to build with the value (and a folder), the name
# messages give it, the object a named bound reads
ARGUMENTS = [
    (MAX_RATE, lambda v, _: RateLimitedTracker(v, 1.0, 0.01), "tracker.max_rate", None),
    (MAX_ACCEL, lambda v, _: RateLimitedTracker(1.0, v, 0.01), "tracker.max_accel", None),
    (TIME_STEP, lambda v, _: RateLimitedTracker(1.0, 1.0, v), "tracker.dt", None),
    (MAX_RATE, lambda v, _: _move(max_rate=v), "move.max_rate", None),
    (MAX_ACCEL, lambda v, _: _move(max_accel=v), "move.max_accel", None),
    (MAX_JERK, lambda v, _: _move(max_jerk=v), "move.max_jerk", None),
    (STOP_ACCEL, lambda v, _: _move(stop_accel=v), "move.stop_accel", types.SimpleNamespace(max_accel=2.0)),
    (BANDWIDTH, lambda v, _: CriticallyDampedSmoother(v, 0.01), "smoother.bandwidth", None),
    (TIME_STEP, lambda v, _: CriticallyDampedSmoother(10.0, v), "smoother.dt", None),
    (STAGES, lambda v, _: CriticallyDampedSmoother(10.0, 0.01, v), "smoother.stages", None),
    (tracking_filter.BANDWIDTH, lambda v, _: TrackingFilter(ONES, ONES, ONES, v, 0.01), "tracking_filter.bandwidth", None),
    (TIME_STEP, lambda v, _: TrackingFilter(ONES, ONES, ONES, 35.0, v), "tracking_filter.period", None),
    (CLEARANCE, lambda v, _: MotionChecker(_robot_scene(), clearance=v), "collision.clearance", None),
    (MAX_JOINT_STEP, lambda v, _: MotionChecker(_robot_scene(), max_joint_step=v), "collision.max_joint_step", None),
    (PARTICLE_RADIUS, _recorder, "recording.particle_radius", None),
    (SAMPLE_RATE, lambda v, _: TrajectoryRecorder((), v), "trajectory.sample_rate_hz", None),
    (SEED, lambda v, folder: parse_sweep({"seed": v, "axes": {"liquid.fill_depth": [0.1]}}, folder, "s"), "seed", None),
    (POURS, lambda v, folder: parse_sweep({"axes": {"fluid.particles_across": {"start": 16, "stop": 32, "num": v}}},
                                          folder, "s"), "axes.fluid.particles_across.num", None),
]


@pytest.mark.parametrize("spec, build, name, owner", ARGUMENTS, ids=[a[2] for a in ARGUMENTS])
def test_each_declared_argument_is_refused_one_step_outside_its_bounds_by_what_takes_it(tmp_path, spec, build, name, owner):
    unit = f" {spec.unit}" if spec.unit else ""
    for value in outside(spec, owner):
        with pytest.raises(InputError) as err:
            build(value, tmp_path)
        assert str(err.value).startswith(f"{name}: must be in {spec.bounds.of(owner).text()}{unit}, got "), err.value
        assert "\n" not in str(err.value)
    # the declaration accepts its bounds (a building block need not work at a rate limit of 5e-324: ruckig finds no
    # profile there, so what builds it is not asked to)
    for value in inside(spec, owner):
        assert spec.check(name, value, owner) == value
