"""The same bits on every x86-64 machine with AVX2: numpy's OpenBLAS kernels pinned before numpy loads.

numpy's OpenBLAS is built for many CPUs at once (DYNAMIC_ARCH) and picks its kernels for the CPU it runs on: CPUs
with AVX-512 get its SkylakeX kernels, AVX2-only ones its Haswell kernels. Their results differ in the last bit, and
a pour is chaotic: the controller's and the IK's small matrix products and solves differ in the last bit, and the
pour that follows is another one (docs/reproducibility.md has the pours measured under each). warp's kernels built
for other instruction sets and numpy without its AVX-512 paths changed nothing. So where the CPU has what the
Haswell kernels need (AVX2 and FMA), they are pinned. Slower kernels for large matrices cost nothing here (the
matrices are a few rows by a few columns). This only works before numpy is first imported (OpenBLAS reads the
variable once, when it loads), so the ``cosim`` command (:func:`cosim.cli.main.main`) and the test suite's
``conftest.py`` call :func:`pin_openblas_core` before anything imports numpy; importing ``cosim`` does not (the other
entry points, such as ``python -m cosim.bench.host_overhead``, run the kernels ``OPENBLAS_CORETYPE`` names in their
environment). A user's own ``OPENBLAS_CORETYPE`` is left alone.

The kernels' bits also change with OpenBLAS's version, which numpy's wheel bundles (two numpy releases with two
OpenBLAS versions give two trajectories; docs/reproducibility.md). So :func:`blas_description` names the BLAS and its kernels beside the package versions a pour's summary records.
"""

from __future__ import annotations

import os
import platform
import sys
from pathlib import Path

PINNED_CORE = "Haswell"
REQUIRED_FLAGS = frozenset({"avx2", "fma"})  # what the Haswell kernels execute (/proc/cpuinfo names)
CPUINFO = Path("/proc/cpuinfo")


def cpu_flags() -> frozenset[str]:
    """The CPU's feature flags as /proc/cpuinfo lists them (empty where there is no such file)."""
    try:
        for line in CPUINFO.read_text().splitlines():
            if line.startswith("flags"):
                return frozenset(line.split(":", 1)[1].split())
    except OSError:
        pass
    return frozenset()


def openblas_core(machine: str, flags: frozenset[str]) -> str | None:
    """The OpenBLAS core to pin on a CPU (``platform.machine()``, its flags), or None: not x86-64, or without
    the instructions the pinned kernels need (forcing them there would stop the process with an illegal
    instruction)."""
    if machine.lower() not in ("x86_64", "amd64"):
        return None
    return PINNED_CORE if REQUIRED_FLAGS <= flags else None


def pin_openblas_core() -> str | None:
    """Set ``OPENBLAS_CORETYPE`` for numpy's OpenBLAS unless it is set already or numpy is loaded (too late then);
    returns the core pinned, or None."""
    if "OPENBLAS_CORETYPE" in os.environ or "numpy" in sys.modules:
        return None
    core = openblas_core(platform.machine(), cpu_flags())
    if core is not None:
        os.environ["OPENBLAS_CORETYPE"] = core
    return core


def blas_description() -> str:
    """numpy's BLAS library and version (as numpy was built with it; its wheels bundle that one) and the OpenBLAS
    kernels asked for, e.g. 'scipy-openblas 0.3.31.188.0 (Haswell kernels)'."""
    import numpy as np

    try:
        blas = np.show_config(mode="dicts")["Build Dependencies"]["blas"]
        library = f"{blas['name']} {blas['version']}"
    except (KeyError, TypeError, ValueError):  # a numpy built without that record
        library = "unknown"
    core = os.environ.get("OPENBLAS_CORETYPE")
    return f"{library} ({core + ' kernels' if core else 'kernels chosen by OpenBLAS for this CPU'})"
