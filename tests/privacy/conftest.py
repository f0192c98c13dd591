"""What the privacy tests share: a calendar a test turns forward."""

from __future__ import annotations


class Calendar:
    """A clock of seconds since the epoch that a test turns forward."""

    def __init__(self, now: float) -> None:
        self.t = now

    def now(self) -> float:
        return self.t
