"""A mesh vessel's regions for the leak check of :mod:`cosim.validation.scripted`, from the mesh itself.

The wall solid is the mesh's inside (the sign of its signed distance, warp's mesh query on the CPU), the inner volume
its cavity (:mod:`cosim.fluid.mesh_boundary`), the column above the opening the space over the cavity's bounding box
that is neither. The same queries as the solver's, but on the sampled positions alone: independent of its guard.
"""

from __future__ import annotations

import numpy as np

from cosim.fluid.mesh_sampling import MeshQueries
from cosim.vessel import VesselSpec


class MeshWallRegions:
    """:class:`cosim.validation.scripted.WallRegions` for a mesh vessel: ``h`` the crest's height (m) and
    :meth:`classify`."""

    def __init__(self, spec: VesselSpec):
        self.h = spec.inner_height
        self.queries = MeshQueries(spec)
        self.reach = float(np.max(np.ptp(spec.mesh.bounds, axis=0)))

    def classify(self, local: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(inside the wall solid, in the inner volume, above the opening) for vessel-frame points (N, 3)."""
        inside, _, _, solid = self.queries.classify(local, self.reach)
        lo, hi = self.queries.cavity
        over = np.all((local[:, :2] > lo[:2]) & (local[:, :2] < hi[:2]), axis=1) & (local[:, 2] >= hi[2])
        return solid, inside, over & ~inside & ~solid
