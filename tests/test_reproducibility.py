"""numpy's OpenBLAS kernels are pinned where the CPU can run them (cosim.reproducibility)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

import cosim.reproducibility as rep
from cosim.reproducibility import PINNED_CORE, openblas_core


@pytest.mark.parametrize(
    "machine,flags,core",
    [
        ("x86_64", {"sse2", "avx", "avx2", "fma", "avx512f"}, PINNED_CORE),
        ("x86_64", {"sse2", "avx2", "fma"}, PINNED_CORE),
        ("AMD64", {"avx2", "fma"}, PINNED_CORE),
        ("x86_64", {"sse2", "avx"}, None),  # no AVX2: the Haswell kernels would be illegal instructions
        ("x86_64", {"avx2"}, None),  # no FMA
        ("aarch64", {"fp", "asimd"}, None),
        ("arm64", set(), None),
    ],
)
def test_the_core_pinned_by_cpu(machine, flags, core):
    assert openblas_core(machine, frozenset(flags)) == core


def test_a_users_setting_or_a_loaded_numpy_is_left_alone(monkeypatch):
    monkeypatch.setattr(rep, "cpu_flags", lambda: frozenset({"avx2", "fma"}))
    monkeypatch.setattr(rep.platform, "machine", lambda: "x86_64")
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Zen")
    assert rep.pin_openblas_core() is None and os.environ["OPENBLAS_CORETYPE"] == "Zen"
    monkeypatch.delenv("OPENBLAS_CORETYPE")
    monkeypatch.setitem(sys.modules, "numpy", sys.modules.get("numpy", object()))  # loaded: too late to pin
    assert rep.pin_openblas_core() is None and "OPENBLAS_CORETYPE" not in os.environ
    monkeypatch.delitem(sys.modules, "numpy")
    assert rep.pin_openblas_core() == PINNED_CORE and os.environ["OPENBLAS_CORETYPE"] == PINNED_CORE


def _corename_probe() -> str:
    """A program printing the core numpy's OpenBLAS runs after the cosim command's start (``cosim --version``, run
    in the same process), or '?' where the build does not say."""
    return """
import contextlib, ctypes, glob, io, os
from cosim.cli.main import main
with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):
    main(["--version"])
import numpy
names = ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename", "openblas_get_corename64_", "openblas_get_corename")
for path in glob.glob(os.path.join(os.path.dirname(numpy.__file__), os.pardir, "numpy.libs", "*openblas*")):
    lib = ctypes.CDLL(path)
    for name in names:
        if hasattr(lib, name):
            getattr(lib, name).restype = ctypes.c_char_p
            print(getattr(lib, name)().decode())
            raise SystemExit
print("?")
"""


def test_the_cosim_command_runs_the_pinned_kernels_on_this_machine():
    expected = openblas_core(rep.platform.machine(), rep.cpu_flags())
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    done = subprocess.run([sys.executable, "-c", _corename_probe()], env=env, capture_output=True, text=True, check=True)
    core = done.stdout.strip()
    if core == "?":
        pytest.skip("this numpy's OpenBLAS does not report its core")
    if expected is None:
        pytest.skip("this CPU gets no pinned core (not x86-64 with AVX2 and FMA)")
    assert core == expected


def test_vessel_masses_are_summed_left_to_right_on_every_python_version():
    from cosim.robots.scene_config import default_catching_vessel, seed_pouring_vessel
    from cosim.vessel import _left_to_right_sum

    # Python 3.12's sum() compensates its rounding (here 2.0), 3.11's adds left to right (0.0)
    assert _left_to_right_sum([1.0, 1e100, 1.0, -1e100]) == 0.0
    # the default vessels' wall volumes, left to right: Python 3.12's sum() gives each one ulp less
    assert seed_pouring_vessel().wall_volume.hex() == "0x1.6760e24300b0cp-11"
    assert default_catching_vessel().wall_volume.hex() == "0x1.c219eb6390c93p-11"


def test_a_pours_versions_name_numpys_blas_and_its_kernels(monkeypatch):
    import numpy as np

    from cosim.pour_run import package_versions
    from cosim.reproducibility import blas_description

    blas = np.show_config(mode="dicts")["Build Dependencies"]["blas"]
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Haswell")
    assert blas_description() == f"{blas['name']} {blas['version']} (Haswell kernels)"
    assert package_versions()["blas"] == blas_description()
    monkeypatch.delenv("OPENBLAS_CORETYPE")
    assert blas_description().endswith(" (kernels chosen by OpenBLAS for this CPU)")
