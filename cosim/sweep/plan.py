"""A sweep's pours, keyed for this code version, and which of them are done, failed or still to run."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cosim.sweep.expand import SweepPoint, expand
from cosim.sweep.resources import PourResources, pour_resources
from cosim.sweep.spec import SweepSpec
from cosim.sweep.store import SweepStore, code_id, code_version, pour_key

# A refused scene has no key: it is failed before anything runs (and again on every rerun, at no cost).
REFUSED_KIND = "bad input"


@dataclass(frozen=True)
class PlannedPour:
    """point: the sweep point (its axes and scene).   key: its store key (None for a refused scene).
    resources: what its Ray task asks for (None for a refused scene)."""

    point: SweepPoint
    key: str | None
    resources: PourResources | None


@dataclass(frozen=True)
class SweepPlan:
    """spec: the sweep.   store: its output.   code: the code id of this process's code.
    version: that code version (source hash, package versions).   pours: every pour, in order."""

    spec: SweepSpec
    store: SweepStore
    code: str
    version: dict[str, str]
    pours: tuple[PlannedPour, ...]

    def to_run(self) -> list[PlannedPour]:
        """The pours with a scene and no complete run folder: never run, failed before, or interrupted."""
        return [p for p in self.pours if p.key is not None and not self.store.is_complete(p.key)]

    def status(self, pour: PlannedPour) -> str:
        """'done', 'failed' (recorded, or a refused scene) or 'not run'."""
        if pour.key is None:
            return "failed"
        if self.store.is_complete(pour.key):
            return "done"
        return "failed" if self.store.failure(pour.key) else "not run"

    def failure(self, pour: PlannedPour) -> dict | None:
        """The pour's failure (kind, error), or None."""
        if pour.key is None:
            return {"kind": REFUSED_KIND, "error": pour.point.error}
        return None if self.store.is_complete(pour.key) else self.store.failure(pour.key)


def plan_sweep(spec: SweepSpec, out: Path) -> SweepPlan:
    """Expand ``spec`` and key its pours for the code this process runs, stored under ``out``."""
    version = code_version()
    code = code_id(version)
    pours = tuple(
        PlannedPour(p, None, None) if p.scene is None else PlannedPour(p, pour_key(p.scene, code), pour_resources(p.scene))
        for p in expand(spec)
    )
    return SweepPlan(spec, SweepStore(out), code, version, pours)
