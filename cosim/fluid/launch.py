"""Kernel launches with their arguments by name.

``wp.launch`` takes a kernel's arguments as positional lists; the SPH kernels take 20 to 35 of them, so a list at the
call site is only checked by its length and types, and two arrays of one type swapped go unnoticed. Here every
argument is given by the kernel's own parameter name and put in the kernel's order from its signature; a missing or
unknown name is an error at recording time.
"""

from __future__ import annotations

from typing import Any, Callable, Mapping

import warp as wp


def kernel_arguments(kernel, args: Mapping[str, Any]) -> list:
    """``args`` (parameter name -> value) as the positional list ``wp.launch`` takes, in ``kernel``'s parameter
    order. Raises TypeError naming every missing and every unknown parameter."""
    names = [arg.label for arg in kernel.adj.args]
    missing = [name for name in names if name not in args]
    unknown = [name for name in args if name not in names]
    if missing or unknown:
        raise TypeError(f"kernel {kernel.key}: missing arguments {missing}, unknown arguments {unknown}")
    return [args[name] for name in names]


def record_launch(kernel, dim, device, args: Mapping[str, Any]) -> Callable[[], None]:
    """``kernel`` over ``dim`` threads with ``args`` by name, recorded with its arguments bound once (warp's
    ``record_cmd``: no argument packing per call); returns the call that runs it."""
    return wp.launch(kernel, dim=dim, inputs=kernel_arguments(kernel, args), device=device, record_cmd=True).launch


def launch_now(kernel, dim, device, args: Mapping[str, Any]) -> None:
    """``kernel`` over ``dim`` threads with ``args`` by name, run at once (one-off set-up work)."""
    wp.launch(kernel, dim=dim, inputs=kernel_arguments(kernel, args), device=device)
