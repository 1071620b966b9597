"""The pours of a sweep as Ray tasks, with a progress bar; a failed pour is recorded and the sweep goes on.

Each pour is one task holding the CPUs or the GPU its scene needs (:mod:`cosim.sweep.resources`). Its worker first
checks that it runs the sweep's code version (a cluster node with other source files or package versions would
write another code's results under this code's key), then runs :func:`cosim.pour_run.run_pour` into the pour's run
folder, which appears only complete. A task is not retried: an error in the pour (a refused scene, an
instability) or a lost worker (killed, its node gone) is recorded with its kind and one line, and the next run of
the sweep runs the pour again.
"""

from __future__ import annotations

import logging
import socket
import warnings
from collections import deque
from pathlib import Path
from typing import TYPE_CHECKING

from cosim.errors import InputError, SimulationError
from cosim.sweep.resources import worker_scene

if TYPE_CHECKING:
    from cosim.pour_scene import PourScene
    from cosim.sweep.plan import PlannedPour, SweepPlan

WAIT_S = 1.0  # s between progress updates while no pour finishes


class CodeVersionMismatch(RuntimeError):
    """A worker runs other code (source files or package versions) than the sweep's driver."""


def pour_task(scene: PourScene, folder: str, code: str) -> None:
    """Run in a Ray worker: one pour of ``scene`` into the run folder ``folder`` (must not exist or be empty), if
    this worker runs the code whose id is ``code``."""
    from cosim.pour_run import run_pour
    from cosim.sweep.store import code_id, code_version

    mine = code_id(code_version())
    if mine != code:
        raise CodeVersionMismatch(f"this worker runs code version {mine}, the sweep {code} (install the same "
                                  f"cosim source and package versions on every node)")
    run_pour(worker_scene(scene), Path(folder), progress=False, long_run_ok=True)


def failure(exc: BaseException) -> dict[str, str]:
    """A failed pour's kind ('bad input', 'simulation failed', 'code version', 'lost worker' or 'error (<type>)') and
    its first line; ``exc`` is the pour's own exception, or Ray's wrapping of it."""
    from controllers.errors import ControllerInputError, MeasurementError

    cause = getattr(exc, "cause", None) or exc  # a task's own exception, inside Ray's RayTaskError
    if isinstance(cause, (InputError, ControllerInputError)):
        kind = "bad input"
    elif isinstance(cause, (SimulationError, MeasurementError)):
        kind = "simulation failed"
    elif isinstance(cause, CodeVersionMismatch):
        kind = "code version"
    else:
        import ray.exceptions

        lost = (ray.exceptions.WorkerCrashedError, ray.exceptions.NodeDiedError, ray.exceptions.ObjectLostError)
        kind = "lost worker" if isinstance(exc, lost) else f"error ({type(cause).__name__})"
    lines = str(cause).strip().splitlines() or [type(cause).__name__]
    return {"kind": kind, "error": lines[0]}


def failure_record(pour: PlannedPour, exc: BaseException) -> dict:
    """What is kept of a failed pour: its axes, the failure's kind and its first line (:func:`failure`)."""
    return {"axes": pour.point.axes, **failure(exc)}


CONNECT_TIMEOUT = 5.0  # s: a Ray head answers a TCP connection at once; Ray's own client retries for minutes


def check_listening(address: str) -> None:
    """Refuse a '[ray://]HOST:PORT' ``address`` (a head's, or a Ray Client server's) at which nothing accepts a TCP
    connection within :data:`CONNECT_TIMEOUT` (Ray retries a head's address for minutes, logging each try; Ray Client
    waits 30 s)."""
    host, _, port = address.removeprefix("ray://").rpartition(":")
    try:
        socket.create_connection((host, int(port)), timeout=CONNECT_TIMEOUT).close()
    except (OSError, ValueError) as exc:
        raise InputError(f"--address: no Ray cluster at {address} (nothing accepts a connection there: "
                         f"{getattr(exc, 'strerror', None) or exc})") from None


def connect(address: str | None) -> bool:
    """Join the Ray cluster at ``address`` ('auto': the one started on this machine with ``ray start``), or start a
    local one on this machine's cores when None; nothing when this process is connected already. Returns whether it
    connected (the caller then disconnects)."""
    import ray

    if ray.is_initialized():
        return False
    if address and address != "auto":
        check_listening(address)
    # Ray Client logs the settings it passes to the server and warns of a timeout before it raises it: the outcome
    # is this function's one line
    client_log = logging.getLogger("ray.client_builder")
    level = client_log.level
    client_log.setLevel(logging.WARNING)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ray.init(address=address, include_dashboard=False, log_to_driver=False)
    except ConnectionError as exc:
        raise InputError(f"--address: no Ray cluster at {address} ({str(exc).splitlines()[0]})") from None
    except ValueError as exc:  # an address Ray cannot use here (a Ray Client address without ray[client])
        raise InputError(f"--address: {address}: {str(exc).strip().splitlines()[0]}") from None
    finally:
        client_log.setLevel(level)
    return True


def run_pours(plan: SweepPlan, max_parallel: int | None = None, progress: bool = True) -> dict[str, int]:
    """Run every pour of ``plan`` not done yet, at most ``max_parallel`` at once (None: as many as the cluster's
    resources hold); returns how many succeeded and failed. Ctrl-C cancels the pours in flight (each removes its
    partial folder) and is raised on."""
    import ray
    from tqdm import tqdm

    task = ray.remote(pour_task)
    queue = deque(plan.to_run())
    in_flight: dict = {}
    counts = {"done": 0, "failed": 0}
    bar = tqdm(total=len(queue), unit="pour", desc="sweep", disable=not progress, dynamic_ncols=True)

    def show() -> None:
        bar.set_postfix_str(f"done {counts['done']}, failed {counts['failed']}, running or queued {len(in_flight)}")

    try:
        while queue or in_flight:
            while queue and (max_parallel is None or len(in_flight) < max_parallel):
                pour = queue.popleft()
                plan.store.remove_partial(pour.key)
                options = dict(num_cpus=pour.resources.cpus, num_gpus=pour.resources.gpus, max_retries=0,
                               name=f"pour-{pour.point.index}")
                ref = task.options(**options).remote(pour.point.scene, str(plan.store.run_folder(pour.key)), plan.code)
                in_flight[ref] = pour
            show()
            ready, _ = ray.wait(list(in_flight), num_returns=1, timeout=WAIT_S)
            for ref in ready:
                pour = in_flight.pop(ref)
                try:
                    ray.get(ref)
                except Exception as exc:  # every failure of one pour is recorded; the sweep goes on
                    plan.store.record_failure(pour.key, failure_record(pour, exc))
                    counts["failed"] += 1
                else:
                    plan.store.clear_failure(pour.key)
                    counts["done"] += 1
                show()
                bar.update(1)
    except KeyboardInterrupt:
        for ref in in_flight:
            ray.cancel(ref)
        raise
    finally:
        show()
        bar.close()
    return counts
