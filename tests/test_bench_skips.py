"""Scene skip options the bench measures: the early stop can be turned off."""

from types import SimpleNamespace

from cosim.coupling.loop import CoupledPour
from cosim.coupling.settings import CouplingSettings


def _finished(time: float, done_at: float | None, settings: CouplingSettings) -> bool:
    return CoupledPour.finished.fget(SimpleNamespace(time=time, done_at=done_at, settings=settings))


def test_early_stop_ends_the_run_settle_time_after_done_unless_turned_off():
    stop = CouplingSettings(settle_time=1.0, max_duration=20.0)
    run_on = CouplingSettings(settle_time=1.0, max_duration=20.0, stop_when_done=False)
    assert not _finished(5.5, 5.0, stop) and _finished(6.0, 5.0, stop)
    assert not _finished(6.0, 5.0, run_on) and not _finished(19.9, 5.0, run_on)
    assert _finished(20.0, 5.0, run_on) and _finished(20.0, None, stop)
    assert not _finished(10.0, None, stop)
