"""Where DFSPH's pair lists lie (cosim.fluid.pair_slots): packed by blocks on the CPU, rows, columns."""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

from cosim.fluid.pair_slots import PAIR_BLOCK, PairSlots, close_pair_row, open_pair_row, pair_slots

CAPACITY = 5


@wp.kernel
def build_rows(slots: PairSlots, counts: wp.array(dtype=wp.int32), table: wp.array(dtype=wp.int32)):
    """Particle i's list: counts[i] entries 1000 i + k, built as the pair-list kernels build theirs."""
    i = wp.tid()
    first = open_pair_row(slots, i)
    for k in range(counts[i]):
        table[first + k * slots.step] = 1000 * i + k
    close_pair_row(slots, i, first, counts[i])


def built(n: int, by_column: bool, packed: bool, counts: np.ndarray):
    slots = pair_slots(n, CAPACITY, "cpu", by_column, packed)
    table = wp.full(n * CAPACITY, -1, dtype=wp.int32, device="cpu")
    wp.launch(build_rows, n, inputs=[slots, wp.array(counts, dtype=wp.int32, device="cpu"), table], device="cpu")
    return slots.start.numpy(), slots.step, table.numpy()


@pytest.mark.parametrize("by_column, packed", [(False, True), (False, False), (True, False)], ids=["packed", "rows", "columns"])
def test_every_layout_keeps_each_list_whole_and_apart(by_column, packed):
    n = 2 * PAIR_BLOCK + 3  # a last block that is not full
    counts = np.random.default_rng(3).integers(0, CAPACITY + 1, n)
    counts[PAIR_BLOCK] = 0  # a block whose first particle has no neighbour
    start, step, table = built(n, by_column, packed, counts)
    for i in range(n):
        assert [table[start[i] + k * step] for k in range(counts[i])] == [1000 * i + k for k in range(counts[i])]
    assert (table >= 0).sum() == counts.sum()  # no list overwrote another's entries


def test_packed_lists_follow_each_other_within_a_block():
    n = 3 * PAIR_BLOCK
    counts = np.full(n, CAPACITY, dtype=np.int32)
    counts[1::2] = 2
    start, step, _ = built(n, by_column=False, packed=True, counts=counts)
    assert step == 1
    for block in range(3):
        first = block * PAIR_BLOCK
        expected = first * CAPACITY + np.concatenate([[0], np.cumsum(counts[first : first + PAIR_BLOCK - 1])])
        np.testing.assert_array_equal(start[first : first + PAIR_BLOCK], expected)


def test_packing_is_refused_where_a_launch_runs_its_threads_at_once(monkeypatch):
    class Cuda:
        is_cuda = True

    monkeypatch.setattr(wp, "get_device", lambda device=None: Cuda())
    with pytest.raises(ValueError, match="packed"):
        pair_slots(10, CAPACITY, "cuda:0", by_column=False, packed=True)
