"""The one way vest runs a worker beside the robot or the service.

A worker is :class:`Work`: it says when its next round is due (clock seconds) and runs one
round. Two runners run any worker:

- :class:`WorkerThread`, a thread of its own that waits on the clock until the round is
  due (:meth:`~engine.clock.Clock.wait` on its stop event, so a virtual clock drives it as
  it drives the scheduler, and stopping never waits out a period);
- :class:`WorkerHook`, a scheduler hook that runs every round due by the step, in order:
  inline on a virtual clock (``vest run --fast``, tests), so a run is the same every time.

Both log a round that raised once per streak of failures (with its traceback) and once
when rounds work again; the worker lives on. Stopping a thread waits at most
:data:`STOP_WAIT_S` for the round in progress: a round stuck on a dying device is left to
end by itself, and the log says so. :class:`Every` is the plain periodic worker (hot
reload, the cloud service's upkeep, the ROS 2 command sweep, telemetry);
:class:`Periodic` runs one on a thread. The pollers and the camera are workers too
(:mod:`engine.hardware.pollers`, :mod:`engine.robot_io.hand_watcher`).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Protocol

from engine.clock import Clock

log = logging.getLogger(__name__)

STOP_WAIT_S = 5.0
"""The one join policy: how long (real seconds) stopping waits for a round in progress."""
AFTER_FAILURE_S = 1.0
"""After a round that failed, the next comes this long after it at the soonest (clock
seconds): a work that fails before moving its deadline on never spins."""
DUE_SLACK_S = 1e-9
"""A round due within this of a step counts as due (deadlines are sums of periods)."""


class Work(Protocol):
    """What a runner runs: ``due_s()`` is when the next round is due (clock seconds; at
    once when it has passed), ``run(now_s)`` is one round at ``now_s``."""

    name: str

    def due_s(self) -> float: ...

    def run(self, now_s: float) -> None: ...


class Rounds:
    """Runs ``work``'s rounds and keeps its failures: ``failures`` in all, logged once per
    streak; a round that raises never ends the worker."""

    def __init__(self, work: Work) -> None:
        self.work = work
        self.rounds = 0
        self.failures = 0
        self._streak = 0
        self._failed_at_s = float("-inf")

    def due_s(self, now_s: float) -> float:
        """When the work is next due (clock seconds): :data:`AFTER_FAILURE_S` after a round
        that failed at the soonest; a work that cannot say (it raised) is asked again then,
        counted as a failed round (never a dead worker)."""
        try:
            due_s = self.work.due_s()
        except Exception:
            self._failed(now_s)
            return now_s + AFTER_FAILURE_S
        return max(due_s, self._failed_at_s + AFTER_FAILURE_S) if self._streak else due_s

    def once(self, now_s: float) -> bool:
        """One round at ``now_s`` (clock seconds); False when it raised."""
        self.rounds += 1
        try:
            self.work.run(now_s)
        except Exception:
            self._failed(now_s)
            return False
        if self._streak:
            log.info("%s works again after %d failed rounds", self.work.name, self._streak)
            self._streak = 0
        return True

    def _failed(self, now_s: float) -> None:
        """(In an ``except``.) Counted; logged with its traceback once per streak."""
        self._failed_at_s = now_s
        self.failures += 1
        self._streak += 1
        if self._streak == 1:
            log.exception("%s: a round failed; the next comes when due", self.work.name)


class WorkerHook:
    """A scheduler hook: every round of ``work`` due by the step's time, in order."""

    def __init__(self, work: Work) -> None:
        self.rounds = Rounds(work)

    def __call__(self, now_s: float) -> None:
        while self.rounds.due_s(now_s) <= now_s + DUE_SLACK_S:
            if not self.rounds.once(now_s):  # it may not have moved on: the next step tries
                return


class WorkerThread:
    """Runs ``work`` on a thread named after it, each round when due on ``clock``, until
    :meth:`stop`; ``after`` runs on that thread once it ends (a final round, closing a
    device only the thread touches)."""

    def __init__(
        self, work: Work, clock: Clock, *, after: Callable[[], None] | None = None
    ) -> None:
        self.rounds = Rounds(work)
        self.clock = clock
        self.after = after
        self._stop = clock.event()
        self._thread: threading.Thread | None = None

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def start(self) -> None:
        """Begin (again, after a stop); a worker already running, or still ending its last
        round after a stop, is left as it is."""
        if self._thread is not None and not self._thread.is_alive():
            self._thread = None
        if self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(
                target=self._run, name=self.rounds.work.name, daemon=True
            )
            self._thread.start()

    def stop(self) -> bool:
        """Ask the thread to end and wait for it (:data:`STOP_WAIT_S` at most); False when
        a round was still running then: it ends by itself (``after`` with it), and until
        it has, :meth:`start` starts no second thread beside it."""
        self._stop.set()
        thread = self._thread
        if thread is None:
            return True
        thread.join(STOP_WAIT_S)
        if thread.is_alive():
            log.warning("%s: still in a round; it ends by itself", thread.name)
            return False
        self._thread = None
        return True

    def _run(self) -> None:
        try:
            while not self.clock.wait(
                self._stop, self.rounds.due_s(self.clock.now()) - self.clock.now()
            ):
                self.rounds.once(self.clock.now())
        finally:
            if self.after is not None:
                self.after()


class Every:
    """``work()`` every ``every_s`` seconds of ``clock``'s time, counted from the end of
    the last round (the first one period after the worker starts)."""

    def __init__(self, clock: Clock, every_s: float, work: Callable[[], object], *, name: str):
        self.clock = clock
        self.every_s = every_s
        self.work = work
        self.name = name
        self._next_s: float | None = None

    def due_s(self) -> float:
        if self._next_s is None:
            self._next_s = self.clock.now() + self.every_s
        return self._next_s

    def run(self, now_s: float) -> None:
        try:
            self.work()
        finally:
            self._next_s = None  # one period from now

    def restart(self) -> None:
        """The next round one period after the next look."""
        self._next_s = None


class Periodic:
    """``work`` every ``every_s`` seconds of ``clock``'s time on a thread named ``name``
    (an :class:`Every` on a :class:`WorkerThread`); ``final``: once more when stopped."""

    def __init__(
        self,
        clock: Clock,
        every_s: float,
        work: Callable[[], object],
        *,
        name: str,
        final: bool = False,
    ) -> None:
        self.every = Every(clock, every_s, work, name=name)
        self._thread = WorkerThread(self.every, clock, after=self._final if final else None)

    @property
    def running(self) -> bool:
        return self._thread.running

    def start(self) -> None:
        """Begin (again, after a stop); a worker already running is left as it is."""
        if not self.running:
            self.every.restart()
        self._thread.start()

    def stop(self) -> None:
        """End the worker (a round in progress finishes first), then the final round."""
        self._thread.stop()

    def _final(self) -> None:
        self._thread.rounds.once(self.every.clock.now())
