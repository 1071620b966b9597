"""numpy's OpenBLAS runs on one thread under the cosim command (cosim.blas_threads)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

import cosim.blas_threads as bt


def test_a_users_setting_or_a_loaded_numpy_is_left_alone(monkeypatch):
    monkeypatch.setenv(bt.VARIABLE, "4")
    assert not bt.limit_openblas_threads() and os.environ[bt.VARIABLE] == "4"
    monkeypatch.delenv(bt.VARIABLE)
    monkeypatch.setitem(sys.modules, "numpy", sys.modules.get("numpy", object()))  # loaded: too late
    assert not bt.limit_openblas_threads() and bt.VARIABLE not in os.environ
    monkeypatch.delitem(sys.modules, "numpy")
    assert bt.limit_openblas_threads() and os.environ[bt.VARIABLE] == "1"


_THREADS_PROBE = """
import contextlib, ctypes, glob, io, os
from cosim.cli.main import main
with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):
    main(["--version"])
import numpy
names = ("scipy_openblas_get_num_threads64_", "scipy_openblas_get_num_threads", "openblas_get_num_threads64_",
         "openblas_get_num_threads")
for path in glob.glob(os.path.join(os.path.dirname(numpy.__file__), os.pardir, "numpy.libs", "*openblas*")):
    lib = ctypes.CDLL(path)
    for name in names:
        if hasattr(lib, name):
            print(getattr(lib, name)())
            raise SystemExit
print("?")
"""


def test_the_cosim_command_leaves_numpys_openblas_one_thread():
    env = {k: v for k, v in os.environ.items() if k != bt.VARIABLE}
    done = subprocess.run([sys.executable, "-c", _THREADS_PROBE], env=env, capture_output=True, text=True, check=True)
    threads = done.stdout.strip()
    if threads == "?":
        pytest.skip("this numpy's OpenBLAS does not report its threads")
    assert threads == "1"
    # the same probe without the command's setting: OpenBLAS's own choice, a thread per core (on one core the check
    # above could not fail)
    unset = subprocess.run([sys.executable, "-c", _THREADS_PROBE.replace('main(["--version"])', "pass")], env=env,
                           capture_output=True, text=True, check=True)
    assert int(unset.stdout.strip()) > 1 or os.cpu_count() == 1
