"""The fluid's settings are declared once (cosim.fluid.config.FluidConfig): each range is enforced from that
declaration, ``cosim scene --dump`` lists each with its range under its group, and the scene, the validation cases
and the benchmark take their defaults from it."""

from __future__ import annotations

import dataclasses
import math

import pytest

from cosim.bench.config import BenchCase, BenchConfig
from cosim.cli.main import main
from cosim.errors import InputError
from cosim.fluid.config import GROUPS, FluidConfig
from cosim.pour_scene import FluidSettings
from declared_settings.setting import declared, declared_fields
from cosim.validation.common import FluidCaseParams
from tests.support.cli_refusal import refusal
from tests.support.setting_bounds import inside, outside

FLUID = declared_fields(FluidConfig)
BOUNDED = [(name, spec) for name, spec in FLUID if spec.bounds is not None and spec.kind in ("float", "int")]


def test_every_setting_is_declared_in_a_known_group_with_a_meaning():
    assert [f.name for f in dataclasses.fields(FluidConfig)] == [name for name, _ in FLUID]
    for name, spec in FLUID:
        assert spec.group in GROUPS, name
        assert spec.meaning.strip(), name
        assert name in FluidConfig.__doc__  # the generated reference


@pytest.mark.parametrize("name, spec", BOUNDED, ids=[name for name, _ in BOUNDED])
def test_each_range_is_enforced_from_its_declaration(name, spec):
    for value in outside(spec):
        with pytest.raises(InputError) as err:
            FluidConfig(**{name: value})
        message = str(err.value)
        assert message.startswith(f"fluid.{name}: must be in {spec.bounds.text()}") and "\n" not in message
    for value in inside(spec):
        assert getattr(FluidConfig(**{name: value}), name) == value


def test_choices_switches_and_the_gravity_magnitude_are_enforced_from_their_declarations():
    for name, spec in FLUID:
        if spec.kind == "choice":
            with pytest.raises(InputError, match=f"^fluid.{name}: must be one of "):
                FluidConfig(**{name: "no-such-choice"})
        if spec.kind == "bool":
            with pytest.raises(InputError, match=f"^fluid.{name}: must be true or false"):
                FluidConfig(**{name: "yes"})
    g = declared(FluidConfig, "gravity").bounds
    with pytest.raises(InputError, match=r"^fluid.gravity magnitude: must be in \[0.1, 98.1\] m/s\^2"):
        FluidConfig(gravity=(0.0, 0.0, -math.nextafter(g.lo, 0.0)))
    assert FluidConfig(gravity=(0.0, 0.0, -g.hi)).gravity_magnitude == g.hi


def test_the_scene_sets_every_fluid_setting_but_those_the_pour_derives():
    scene = dict(declared_fields(FluidSettings))
    derived = {d.name for d in FluidSettings.derived_settings}
    assert set(scene) - {"particles_across"} | derived == {name for name, _ in FLUID}
    assert not set(scene) & derived
    for d in FluidSettings.derived_settings:
        assert d.spec is declared(FluidConfig, d.name)


def test_the_scene_bench_and_validation_take_the_fluids_declarations_and_defaults():
    for name, spec in declared_fields(FluidSettings):
        if name != "particles_across":
            assert spec == declared(FluidConfig, name), name
            assert getattr(FluidSettings(), name) == getattr(FluidConfig, name), name
    bench = BenchConfig(BenchCase.HYDROSTATIC, 16, 1.0)
    for name in ("dim", "kernel", "cfl", "pressure_solver", "density_tolerance"):
        assert getattr(bench, name) == getattr(FluidConfig, name), name
        assert declared(BenchConfig, name).bounds == declared(FluidConfig, name).bounds, name
    assert bench.smoothing_ratio is None and declared(BenchConfig, "smoothing_ratio").bounds == declared(FluidConfig, "smoothing_ratio").bounds
    case = FluidCaseParams()
    assert (case.dim, case.depth, case.solver) == (FluidConfig.dim, FluidConfig.depth_2d, FluidConfig.pressure_solver)


def test_the_default_scenes_fluid_is_the_declarations_at_its_resolution():
    width = 0.191
    scene = FluidSettings()
    expected = FluidConfig(spacing=width / scene.particles_across)
    assert scene.fluid_config(width) == expected


def _fluid_table(text: str) -> list[str]:
    lines = text.split("[fluid]\n", 1)[1].split("\n[", 1)[0]
    return lines.splitlines()


def test_scene_dump_lists_every_setting_with_its_range_under_its_group(capsys):
    assert main(["scene", "--dump"]) == 0
    table = _fluid_table(capsys.readouterr().out)
    group = None
    seen = {}
    for line in table:
        if line.startswith("# -- ") and line.endswith(" --"):
            group = line[5:-3]
            continue
        for name, spec in FLUID + [("particles_across", declared(FluidSettings, "particles_across"))]:
            if line.startswith((f"{name} = ", f"# {name} = ", f"# {name}: ")):
                seen[name] = (group, line)
    for name, spec in FLUID:
        group, line = seen[name]
        assert f"Allowed: {spec.allowed()}." in line, line
        if name not in {d.name for d in FluidSettings.derived_settings}:
            assert group == spec.group, name
    assert "particles_across" in seen


BAD_SCENE_VALUES = [(name, value) for name, spec in declared_fields(FluidSettings) if spec.bounds is not None
                    for value in outside(spec)]


@pytest.mark.parametrize("name, value", BAD_SCENE_VALUES, ids=[f"{n}={v:g}" for n, v in BAD_SCENE_VALUES])
def test_a_scene_value_outside_its_range_is_one_line_naming_the_field_and_the_range(tmp_path, capsys, name, value):
    path = tmp_path / "bad.toml"
    path.write_text(f"[fluid]\n{name} = {value!r}\n")
    message = refusal(capsys, ["scene", "--check", str(path)], "scene")
    assert f"fluid.{name}: must be in {declared(FluidSettings, name).bounds.text()}" in message
