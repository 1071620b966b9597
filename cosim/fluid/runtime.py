"""warp initialisation, device selection and kernel loading (the only place that calls ``wp.init``).

Nothing here runs on import: a command that runs warp calls :func:`init_warp` (directly or through
:func:`resolve_device`), which sets warp's global configuration once.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from collections.abc import Sequence

import warp as wp

from cosim.errors import InputError

_initialised = False


def init_warp() -> None:
    """Initialise warp once: quiet logging; kernel cache from ``WARP_CACHE_PATH`` if set (warp's default otherwise)."""
    global _initialised
    if _initialised:
        return
    wp.config.log_level = wp.LOG_WARNING
    wp.config.quiet = True
    wp.config.enable_backward = False  # no gradients are taken: skips adjoint code generation (faster compiles)
    cache = os.environ.get("WARP_CACHE_PATH")
    if cache:
        wp.config.kernel_cache_dir = cache
    _init_without_driver_warning()
    _initialised = True


def _init_without_driver_warning() -> None:
    """``wp.init()``, minus the native library's warning that no CUDA driver exists (expected on CPU machines);
    anything else it writes to stderr is passed through."""
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as captured:
        os.dup2(captured.fileno(), 2)
        try:
            wp.init()
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        captured.seek(0)
        text = captured.read().decode(errors="replace")
    for line in text.splitlines():
        if "Could not find or load the NVIDIA CUDA driver" not in line:
            print(line, file=sys.stderr)


def resolve_device(name: str) -> wp.Device:
    """Return the warp device for ``name`` ('cpu', 'cuda', 'cuda:N'); a clear InputError if it is not available."""
    init_warp()
    if name == "cuda":
        name = "cuda:0"
    if name != "cpu" and not name.startswith("cuda:"):
        raise InputError(f"device: must be 'cpu' or 'cuda[:N]', got {name!r}")
    if name.startswith("cuda") and not wp.is_cuda_available():
        raise InputError(f"device: {name!r} requested but no CUDA device is available here (use --device cpu)")
    try:
        return wp.get_device(name)
    except Exception as exc:  # warp raises RuntimeError/ValueError for unknown ordinals
        raise InputError(f"device: {name!r} is not available ({exc})") from None


def cuda_available() -> bool:
    init_warp()
    return wp.is_cuda_available()


def kernel_modules(package: str) -> list[str]:
    """The imported Python modules of ``package`` (e.g. 'cosim') that define warp kernels (not those that only import
    one): warp compiles and caches each as one module, so these are what a run that imported them will load."""
    prefix = package + "."
    return sorted(name for name, module in list(sys.modules.items())
                  if (name == package or name.startswith(prefix)) and module is not None
                  and any(isinstance(value, wp.Kernel) and value.module.name == name for value in vars(module).values()))


def load_kernels(device: wp.Device, modules: Sequence[str]) -> float:
    """Load the warp modules of the Python modules ``modules`` on ``device`` now rather than at their first launch
    (``wp.force_load``, which compiles them in parallel): compiled on a machine's first run, read from warp's kernel
    cache (``wp.config.kernel_cache_dir``) afterwards. Returns the wall time it took, s."""
    init_warp()
    start = time.perf_counter()
    wp.force_load(device=device, modules=[wp.get_module(name) for name in modules])
    return time.perf_counter() - start
