"""Whether the lanes replay a run of substeps all at once or one after another on one thread, chosen by timing both.

Lanes running at once (``cosim.fluid.lanes``) finish a substep sooner only while each has a core to itself: they
meet at a barrier after every stage, tens of times a substep, so a lane that the OS takes off its core for another
process stalls every other lane until it runs again. When the cores are shared, one thread replaying every lane's
share in turn (no barriers) does the same work faster. The particles come out the same to the bit either way, so
the choice is only about wall time, and :class:`ReplayChoice` makes it by measuring: the faster way runs, and the
other is timed again in a short probe, first after :data:`FIRST_PROBE_AFTER` intervals and then at gaps of replay
time that double from :data:`PROBE_GAP_MIN_S` to :data:`PROBE_GAP_MAX_S` while the probes confirm the choice, or
longer, so that the time a probe loses against the current way is at most :data:`PROBE_SHARE` of the replay time
since the last one. So a change of load is noticed within :data:`PROBE_GAP_MAX_S` of replay time where the two ways
cost about the same, and later, but cheaply, where the other way is far slower.
"""

from __future__ import annotations

from collections import deque

# Intervals run all at once before the first probe of the one-thread way: enough to time the lanes, few enough that
# lanes stalled by a busy machine cost little before the switch.
FIRST_PROBE_AFTER = 4
# Intervals of a probe; a probe's first interval ends it when it alone is this many times the current way's cost
# per substep (clearly slower: no second interval needed).
PROBE_INTERVALS = 2
CLEARLY_SLOWER = 1.5
# Replay time (s) between probes: the first gap, doubled after each probe that confirms the choice, up to the last;
# longer where a probe of a much slower way would otherwise cost more than PROBE_SHARE of the replay time.
PROBE_GAP_MIN_S = 0.1
PROBE_GAP_MAX_S = 2.0
PROBE_SHARE = 0.02
# The other way must be this much faster per substep to be switched to (the intervals' costs scatter by a few %).
SWITCH_MARGIN = 0.05
# Intervals of the current way whose mean cost per substep a probe is compared with (the latest ones).
RECENT_INTERVALS = 8


class ReplayChoice:
    """Chooses, interval by interval, between all lanes at once (``parallel() -> True``) and every lane's share on
    one thread, from the wall time per substep each way took (:meth:`record`)."""

    def __init__(self):
        self.current = True  # the lanes at once until timed otherwise
        self._recent: deque[tuple[int, float]] = deque(maxlen=RECENT_INTERVALS)  # (substeps, wall s) of the current way
        self._probe: list[tuple[int, float]] = []  # the running probe's intervals
        self._probing = False
        self._gap_s = PROBE_GAP_MIN_S
        self._since_probe_s = 0.0  # replay time of the current way since the last probe
        self._probed = False

    def parallel(self) -> bool:
        """Whether the next interval runs all lanes at once."""
        return self.current != self._probing

    def record(self, parallel: bool, substeps: int, wall_s: float) -> None:
        """The interval just run: all lanes at once or not, its substeps and their wall time (s)."""
        if substeps <= 0:
            return
        if parallel != self.current:
            self._probe.append((substeps, wall_s))
            if len(self._probe) >= PROBE_INTERVALS or _cost(self._probe) > CLEARLY_SLOWER * _cost(self._recent):
                self._end_probe()
            return
        self._recent.append((substeps, wall_s))
        self._since_probe_s += wall_s
        self._probing = self._since_probe_s >= self._gap_s if self._probed else len(self._recent) >= FIRST_PROBE_AFTER

    def _end_probe(self) -> None:
        if _cost(self._probe) < (1.0 - SWITCH_MARGIN) * _cost(self._recent):
            self.current = not self.current
            self._recent = deque(self._probe, maxlen=RECENT_INTERVALS)
            self._gap_s = PROBE_GAP_MIN_S
        else:
            probe_wall = sum(wall for _, wall in self._probe)
            lost_s = probe_wall - sum(substeps for substeps, _ in self._probe) * _cost(self._recent)
            self._gap_s = max(min(2.0 * self._gap_s, PROBE_GAP_MAX_S), lost_s / PROBE_SHARE)
        self._probe = []
        self._probing = False
        self._probed = True
        self._since_probe_s = 0.0


def _cost(intervals) -> float:
    """Wall s per substep over ``intervals`` ((substeps, wall s) pairs)."""
    return sum(wall for _, wall in intervals) / sum(substeps for substeps, _ in intervals)
