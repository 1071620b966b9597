"""`cosim --help`, every subcommand's `--help` and refused input answer without loading the heavy libraries (each
costs a second or more to import), and importing any module of cosim or controllers changes nothing outside them."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from cosim.bench.startup import BAD_SCENES, write_bad_scenes
from cosim.cli.main import SUBCOMMANDS

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("warp", "mujoco", "control", "scipy", "rerun", "ray")
# Runs `cosim ARGS...` in this process, then prints its exit status and which of the libraries LIBRARIES it imported.
PROBE = """
import contextlib, io, sys
from cosim.cli.main import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    try:
        status = main(sys.argv[1:])
    except SystemExit as exc:
        status = exc.code
print(status, *sorted(name for name in LIBRARIES if name in sys.modules))
"""


def _probe(args: list[str], libraries: tuple[str, ...] = HEAVY) -> list[str]:
    done = subprocess.run([sys.executable, "-c", f"LIBRARIES = {libraries!r}" + PROBE, *args], cwd=ROOT, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


@pytest.fixture(scope="module")
def bad_scene(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("scenes") / "typo.toml"
    path.write_text("[fluid]\nparticles_acros = 32\n")
    return path


@pytest.mark.parametrize("args", [["--help"], []] + [[name, "--help"] for name in SUBCOMMANDS],
                         ids=lambda args: " ".join(args) or "no-args")
def test_help_loads_no_heavy_library(args):
    status, *loaded = _probe(args)
    assert status in ("0", "2") and loaded == []


@pytest.mark.parametrize("args", [["pour", "/nonexistent/scene.toml"], ["pour", "BAD"], ["scene", "--check", "BAD"],
                                  ["pour", "--dim", "4"], ["view", "/nonexistent/run"],
                                  ["sweep", "/nonexistent/sweep.toml"], ["sweep", "BAD"]], ids=" ".join)
def test_refused_input_loads_no_heavy_library(args, bad_scene):
    status, *loaded = _probe([str(bad_scene) if a == "BAD" else a for a in args])
    assert status == "2" and loaded == []


@pytest.mark.parametrize("args", [["pour", "--duration", "-1"], ["pour", "--threads", "-1"], ["pour", "--device", "tpu"]], ids=" ".join)
def test_a_refused_pour_option_loads_not_even_numpy(args):
    """An option's value is checked before the scene (and NumPy with it) is loaded."""
    status, *loaded = _probe(args, ("numpy",))
    assert status == "2" and loaded == []


@pytest.mark.parametrize("command", [["pour"], ["scene", "--check"]], ids=" ".join)
@pytest.mark.parametrize("wrong", list(BAD_SCENES))
def test_a_refused_scene_file_loads_not_even_numpy(command, wrong, tmp_path):
    """A scene file's settings (fluid, controller, vessels, arms) are checked by classes that import no numerics:
    NumPy, ruckig and tomlkit load only for what comes after a good scene."""
    path = write_bad_scenes(tmp_path)[wrong]
    status, *loaded = _probe([*command, str(path)], ("numpy", "ruckig", "tomlkit"))
    assert status == "2" and loaded == []


def test_a_sample_rate_under_two_samples_is_refused_without_numpy(tmp_path):
    """A check across two sections (the trajectory's rate against the run's length) is the scene's own, not the
    pour checks' that load the numerics."""
    path = tmp_path / "rate.toml"
    path.write_text("[trajectory]\nsample_rate_hz = 1e-9\n")
    status, *loaded = _probe(["scene", "--check", str(path)], ("numpy",))
    assert status == "2" and loaded == []


def test_the_controllers_package_gives_each_public_name_from_its_module():
    import importlib

    import controllers

    for name in controllers.__all__:
        module = importlib.import_module(controllers._MODULES[name])
        assert getattr(controllers, name) is getattr(module, name)
    with pytest.raises(AttributeError, match="no attribute 'PourControler'"):
        controllers.PourControler


# Imports every module of cosim and controllers (the packages first, before anything loads numpy, so that a BLAS pin
# at import would show), then prints what changed outside them.
IMPORT_ALL = """
import importlib, importlib.util, json, os, pkgutil
env = dict(os.environ)
import cosim, controllers, declared_settings
import warp as wp

# warp's runtime object (None until wp.init), in warp._src.context in recent releases, warp.context before
context = importlib.import_module("warp._src.context" if importlib.util.find_spec("warp._src") else "warp.context")

def config():
    return {k: repr(v) for k, v in vars(wp.config).items() if not k.startswith("_")}

cfg, names = config(), []
for package in ("cosim", "controllers", "declared_settings"):
    for info in pkgutil.walk_packages(importlib.import_module(package).__path__, package + "."):
        if info.name.rsplit(".", 1)[-1] != "__main__":  # ``python -m cosim`` runs the command
            importlib.import_module(info.name)
            names.append(info.name)
changed_env = sorted(k for k in set(env) | set(os.environ) if env.get(k) != os.environ.get(k))
changed_cfg = sorted(k for k in set(cfg) | set(config()) if cfg.get(k) != config().get(k))
print(json.dumps({"modules": names, "env": changed_env, "warp_config": changed_cfg,
                  "warp_initialised": context.runtime is not None}))
"""


def test_importing_every_module_changes_no_environment_variable_and_no_warp_option():
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"} | {"PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", IMPORT_ALL], cwd=ROOT, capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert "cosim.cli.main" in result["modules"] and "cosim.fluid.solver" in result["modules"]
    assert result["env"] == []
    assert result["warp_config"] == []
    assert result["warp_initialised"] is False


def test_the_pour_loads_the_kernel_modules_it_launches():
    import cosim.pour_run  # noqa: F401  (imports what a pour launches kernels from)
    from cosim.fluid.runtime import kernel_modules

    modules = kernel_modules("cosim")
    assert {"cosim.fluid.dfsph", "cosim.fluid.wcsph", "cosim.fluid.neighbors", "cosim.coupling.measure"} <= set(modules)
    assert "cosim.fluid.sph_kernels" not in modules  # warp functions only: compiled into the kernels that call them
    assert "cosim.fluid.solver" not in modules  # launches kernels it imports: compiled with the modules defining them


def test_exit_status_of_each_error_kind():
    from controllers.errors import ControllerInputError, MeasurementError
    from cosim.cli.main import exit_status
    from cosim.errors import InputError, SimulationError

    assert exit_status(InputError("x")) == 2 and exit_status(ControllerInputError("x")) == 2
    assert exit_status(SimulationError("x")) == 1 and exit_status(MeasurementError("x")) == 1
    assert exit_status(ValueError("x")) is None  # a bug: raised, not reported as bad input
