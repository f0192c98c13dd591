"""Starting a robot's parts in order and stopping them in reverse, with one policy.

Every part that runs beside the trees (pollers, the camera's worker, the reloader, the
cloud link, a page's server...) is added to the robot's :class:`Lifecycle` by the one
place that builds the robot. The policy: parts start in the order they were added; a part
that fails to start stops those already started (in reverse) and the failure is raised;
stopping stops every part that was opened or started, in reverse order, each one even when
an earlier one failed, and then raises the first failure.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Part:
    """A named part: ``start`` (None: nothing to start; it is open once added) and
    ``stop`` (releases what it holds; called once)."""

    name: str
    start: Callable[[], None] | None
    stop: Callable[[], None]


class Lifecycle:
    """The parts of one robot, in the order they start."""

    def __init__(self) -> None:
        self._parts: list[Part] = []
        self._open: list[Part] = []
        self.started = False

    def add(
        self, name: str, *, stop: Callable[[], None], start: Callable[[], None] | None = None
    ) -> None:
        """Add a part; one without ``start`` holds something already (a bus, a file) and
        is stopped whatever happens."""
        part = Part(name, start, stop)
        self._parts.append(part)
        if start is None:
            self._open.append(part)

    def start(self) -> None:
        """Start the parts in order; on a failure stop what was opened and raise it."""
        self.started = True
        for part in self._parts:
            if part.start is None:
                continue
            try:
                part.start()
            except BaseException:
                self.stop()
                raise
            self._open.append(part)

    def stop(self) -> None:
        """Stop every open part, last opened first; raise the first failure at the end."""
        failure: BaseException | None = None
        while self._open:
            part = self._open.pop()
            try:
                part.stop()
            except Exception as error:  # the others still stop
                log.error("stopping %s failed: %s", part.name, error)
                failure = failure or error
        if failure is not None:
            raise failure
