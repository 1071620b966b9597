"""warp initialisation and device selection (the only place that calls ``wp.init``)."""

from __future__ import annotations

import os

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
    wp.init()
    _initialised = True


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
