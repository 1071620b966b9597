"""warp initialisation and device selection (the only place that calls ``wp.init``)."""

from __future__ import annotations

import os
import sys
import tempfile

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
