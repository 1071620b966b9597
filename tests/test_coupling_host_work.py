"""The co-simulation loop does no per-step host work that grows with the particle count.

The host exchanges only a few hundred numbers with the liquid's arrays per control period, whatever the liquid's
size: the controller's probe reduces the particles on the fluid's device (cosim/coupling/measure.py) and the
solver reads back its per-substep diagnostics and the wrench. Spied here: every read-back (``wp.array.numpy``, and
the probe's own read-back point ``LiquidProbe.read_back``, which on the CPU reads through numpy views made once)
and upload (``wp.array.assign``, ``wp.copy``) in the same stretch of the default pour, with the stream falling
(3.0 to 3.2 s), at two resolutions."""

from collections import Counter

import pytest
import warp as wp

from cosim.bench.host_overhead import POUR_WARM_UP, time_steps, warm_pour
from cosim.coupling.measure import CHUNKS, STREAM_SUM_COLUMNS, LiquidProbe

STREAM_SUMS = CHUNKS * STREAM_SUM_COLUMNS  # the probe's partial sums of the leaving stream, per chunk: a fixed size

WARM_SECONDS = 3.0  # s: into the first outflow, so the probe's stream-crossing read-back takes part
SPIED_SECONDS = 0.2  # s: 100 MuJoCo steps of 2 ms, 20 control periods of 10 ms
COARSE, FINE = 16, 24  # particles across the pourer: 208 and 480 particles


def _spied(monkeypatch, pour) -> Counter:
    """(operation, element count) -> calls, over SPIED_SECONDS of ``pour``."""
    seen: Counter = Counter()
    numpy, assign, copy, read_back = wp.array.numpy, wp.array.assign, wp.copy, LiquidProbe.read_back

    def spy_numpy(self):
        seen["read", self.size] += 1
        return numpy(self)

    def spy_assign(self, src):
        seen["upload", self.size] += 1
        return assign(self, src)

    def spy_copy(dest, src, *args, **kwargs):
        seen["copy", src.size] += 1
        return copy(dest, src, *args, **kwargs)

    def spy_read_back(self, array, size=None):
        values = read_back(self, array, size)
        seen["probe read", values.size] += 1
        return values

    with monkeypatch.context() as m:
        m.setattr(wp.array, "numpy", spy_numpy)
        m.setattr(wp.array, "assign", spy_assign)
        m.setattr(wp, "copy", spy_copy)
        m.setattr(LiquidProbe, "read_back", spy_read_back)
        time_steps(pour, SPIED_SECONDS)
    return seen


def _transfers(across: int, monkeypatch) -> tuple[int, Counter]:
    pour = warm_pour("cpu", 2, across, WARM_SECONDS + SPIED_SECONDS, "dfsph", "gauss_seidel")
    time_steps(pour, WARM_SECONDS - POUR_WARM_UP)  # warm_pour stepped the first POUR_WARM_UP
    return pour.fluid.n_particles, _spied(monkeypatch, pour)


@pytest.mark.slow
def test_what_the_host_moves_does_not_grow_with_the_particle_count(monkeypatch):
    coarse_n, coarse = _transfers(COARSE, monkeypatch)
    fine_n, fine = _transfers(FINE, monkeypatch)
    assert fine_n > 2 * coarse_n
    for n, seen in ((coarse_n, coarse), (fine_n, fine)):
        assert seen, "the spy saw nothing: the probe and the diagnostics must read back"
        assert all(size < n for _, size in seen if size != STREAM_SUMS), seen  # no array of one entry per particle
    total = {k: sum(size * calls for (_, size), calls in seen.items()) for k, seen in (("coarse", coarse), ("fine", fine))}
    # the liquid grew 2.3 x; the surface columns the probe reads grow with the particles across (1.5 x), the rest is
    # fixed: the elements moved grow by less than the resolution, far less than the particle count
    assert total["fine"] < (FINE / COARSE) * total["coarse"], (total, coarse, fine)


def test_the_spy_sees_a_per_particle_read_back(monkeypatch):
    # the check above can fail: a read of the particles' positions is seen, at one entry per particle
    pour = warm_pour("cpu", 2, COARSE, 0.01, "dfsph", "gauss_seidel")
    seen: Counter = Counter()
    numpy = wp.array.numpy

    def spy_numpy(self):
        seen[self.size] += 1
        return numpy(self)

    monkeypatch.setattr(wp.array, "numpy", spy_numpy)
    pour.fluid.positions()
    assert seen[pour.fluid.n_particles] >= 1
