"""A periodic worker does its work every period of its clock, survives a bad round, and
stops at once, with its final round when it has one."""

from __future__ import annotations

from engine.clock import VirtualClock
from engine.periodic import Periodic, WorkerHook, WorkerThread


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


class Stubborn:
    """A worker that cannot say when it is due the first ``broken`` times it is asked."""

    name = "stubborn"

    def __init__(self, clock: VirtualClock, broken: int) -> None:
        self.clock, self.broken, self.rounds = clock, broken, 0

    def due_s(self) -> float:
        if self.broken:
            self.broken -= 1
            raise ValueError("no idea")
        return self.clock.now()

    def run(self, now_s: float) -> None:
        self.rounds += 1
        raise OSError("the disk is full")  # and it never moves its deadline on


def test_a_hook_whose_work_fails_gives_the_step_back_and_tries_at_the_next() -> None:
    clock = VirtualClock()
    work = Stubborn(clock, broken=1)
    hook = WorkerHook(work)
    hook(0.0)  # due_s raised: counted, asked again in a second
    assert (hook.rounds.failures, work.rounds) == (1, 0)
    hook(1.0)  # due now, the round fails without moving on: the step goes on all the same
    hook(1.5)  # and the next round comes a second after a failure, not at every step
    hook(2.0)
    assert (hook.rounds.failures, work.rounds) == (3, 2)


def test_a_thread_whose_work_cannot_say_when_it_is_due_lives_on() -> None:
    clock = VirtualClock()
    work = Stubborn(clock, broken=1)
    worker = WorkerThread(work, clock)
    worker.start()
    assert clock.until_waiting(1, entered=1)  # it could not say: a second's wait
    clock.advance(1.0)
    assert clock.until_waiting(1, entered=2)  # a round at 1 s, failed: the next at 2 s
    clock.advance(1.0)
    assert clock.until_waiting(1, entered=3)  # one more, never a spin
    worker.stop()
    assert (work.rounds, worker.rounds.failures, worker.running) == (2, 3, False)
