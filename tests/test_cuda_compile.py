"""Every warp kernel module of the project compiles for the GPU machines' architecture (NVRTC, ahead of time).

A CPU-only test run (CI has no GPU) checks nothing else of the CUDA build: a CPU-only construct in a kernel module
(such as GCC atomics in native code, which the lanes' barrier uses) would otherwise surface only on a GPU. Skipped
where warp has no NVRTC for that architecture."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest
import warp as wp

from cosim.fluid.runtime import init_warp

ROOT = Path(__file__).resolve().parents[1]
# sm_90: NVIDIA's Hopper architecture, that of the GPUs the speed targets are set on
GPU_ARCH = 90


def kernel_modules() -> list[str]:
    """The project's modules that define warp kernels (found by their ``@wp.kernel`` decorators)."""
    files = sorted(f for package in ("cosim", "controllers") for f in (ROOT / package).rglob("*.py") if "@wp.kernel" in f.read_text())
    return [".".join(f.relative_to(ROOT).with_suffix("").parts) for f in files]


def test_the_kernel_modules_are_found():
    assert {"cosim.fluid.dfsph", "cosim.fluid.wcsph", "cosim.fluid.lanes"} <= set(kernel_modules())


@pytest.mark.parametrize("name", kernel_modules())
@pytest.mark.slow
def test_kernel_module_compiles_for_the_gpu(name, tmp_path):
    init_warp()
    if GPU_ARCH not in wp.get_cuda_supported_archs():
        pytest.skip(f"warp has no NVRTC for sm_{GPU_ARCH} here")
    wp.compile_aot_module(importlib.import_module(name), arch=GPU_ARCH, module_dir=tmp_path, use_ptx=True)
    assert list(tmp_path.glob("*.ptx")), f"{name}: no PTX written"
