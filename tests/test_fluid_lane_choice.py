"""The choice between the lanes at once and one thread (``cosim.fluid.lane_choice``), driven by synthetic interval
costs: the choice must cost little against always taking the faster way, and follow a change of load."""

from __future__ import annotations

from cosim.fluid.lane_choice import PROBE_GAP_MAX_S, ReplayChoice

SUBSTEPS = 3  # per interval, as in the default pour (about 3.5 substeps a 2 ms MuJoCo step)
INTERVALS = 1000


def _run(choice: ReplayChoice, cost_ms, intervals: int = INTERVALS) -> float:
    """Drive ``choice`` for ``intervals`` intervals; ``cost_ms(parallel, elapsed_s)`` is the wall ms per substep
    each way costs after ``elapsed_s`` of replay. Returns the total replay time, s."""
    elapsed = 0.0
    for _ in range(intervals):
        parallel = choice.parallel()
        wall = SUBSTEPS * cost_ms(parallel, elapsed) * 1e-3
        choice.record(parallel, SUBSTEPS, wall)
        elapsed += wall
    return elapsed


def test_busy_cores_run_on_one_thread_at_most_a_few_percent_slower():
    # a competing process makes the lanes at once several times slower than one thread
    choice = ReplayChoice()
    total = _run(choice, lambda parallel, _: 7.2 if parallel else 2.0)
    assert not choice.current
    assert total <= 1.05 * INTERVALS * SUBSTEPS * 2.0e-3


def test_free_cores_keep_the_lanes_at_once():
    choice = ReplayChoice()
    total = _run(choice, lambda parallel, _: 1.3 if parallel else 2.0)
    assert choice.current
    assert total <= 1.03 * INTERVALS * SUBSTEPS * 1.3e-3


def test_a_change_of_load_is_followed_both_ways():
    busy_from, busy_until = 2.0, 6.0  # s of replay
    switches = []

    def cost(parallel, elapsed):
        busy = busy_from <= elapsed < busy_until
        return (7.2 if parallel else 2.0) if busy else (1.3 if parallel else 2.0)

    choice, elapsed, last = ReplayChoice(), 0.0, True
    while elapsed < 12.0:
        parallel = choice.parallel()
        wall = SUBSTEPS * cost(parallel, elapsed) * 1e-3
        choice.record(parallel, SUBSTEPS, wall)
        elapsed += wall
        if choice.current != last:
            switches.append((choice.current, elapsed))
            last = choice.current
    assert switches[0][0] is False and busy_from < switches[0][1] < busy_from + PROBE_GAP_MAX_S + 0.1
    # back to the lanes at once after the load is gone: later, as probes of a far slower way are spaced out
    assert switches[1][0] is True and busy_until < switches[1][1] < busy_until + 4 * PROBE_GAP_MAX_S
    assert len(switches) == 2


def test_intervals_without_substeps_are_ignored():
    choice = ReplayChoice()
    for _ in range(10):
        choice.record(choice.parallel(), 0, 0.0)
    assert choice.current and choice.parallel()
