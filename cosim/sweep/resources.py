"""What one pour asks the Ray scheduler for, and the scene its worker runs.

A CPU pour asks for its liquid's threads (``fluid.cpu_threads``; 0, one per core for a single pour, asks for one
CPU: a sweep spreads its pours over the cores instead, and the liquid's results are the same to the bit for any
number of threads). A CUDA pour asks for one GPU and one CPU (the arms, the controller and the kernel launches run
on the host), so a cluster with GPUs puts it there. Ray shows a worker only the GPU it was given
(``CUDA_VISIBLE_DEVICES``), so the worker runs on ``cuda``, whatever ``cuda:N`` the scene names.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from cosim.pour_scene import PourScene


@dataclass(frozen=True)
class PourResources:
    """cpus: CPU cores the pour's task holds.   gpus: GPUs it holds (0 or 1)."""

    cpus: int
    gpus: int

    def __str__(self) -> str:
        return f"{self.cpus} CPU" + (f" + {self.gpus} GPU" if self.gpus else "")


def pour_resources(scene: PourScene) -> PourResources:
    """The Ray resources of a pour of ``scene`` (module docstring)."""
    if scene.device.startswith("cuda"):
        return PourResources(cpus=1, gpus=1)
    return PourResources(cpus=scene.fluid.cpu_threads or 1, gpus=0)


def worker_scene(scene: PourScene) -> PourScene:
    """``scene`` as its Ray worker runs it: on the threads it holds, or on the one GPU Ray shows it."""
    if scene.device.startswith("cuda"):
        return replace(scene, device="cuda")
    return replace(scene, fluid=replace(scene.fluid, cpu_threads=pour_resources(scene).cpus))
