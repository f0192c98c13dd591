"""A periodic worker does its work every period of its clock, survives a bad round, and
stops at once, with its final round when it has one."""

from __future__ import annotations

from engine.clock import VirtualClock
from engine.periodic import Periodic


def test_work_comes_every_period_and_a_bad_round_does_not_end_the_worker() -> None:
    clock = VirtualClock()
    rounds: list[float] = []

    def work() -> None:
        rounds.append(clock.now())
        if len(rounds) == 1:
            raise OSError("the disk is full")  # logged; the next round comes

    worker = Periodic(clock, 1.0, work, name="test-worker", final=True)
    worker.start()
    for entered in (1, 2, 3):
        assert clock.until_waiting(1, entered=entered)
        if entered < 3:
            clock.advance(1.0)
    worker.stop()  # at once, though the next round is a period away
    assert rounds == [1.0, 2.0, 2.0]  # two rounds, then the final one
    assert not worker.running
