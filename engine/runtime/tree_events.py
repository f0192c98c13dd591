"""The event readers of one tree, read as one.

A tree's OnEvent, WaitForEvent and OnTouch nodes each read their key in order
(:class:`~engine.nodes.event_reader.EventReader`). Between rounds the tree answers for them
together: an event one of them took in a round that is over is the tree's, and no other
reacts to it later; a round cut short is tried again from where its readers stood when it
began; a new version of the tree (a reload) takes up where the old one stood; and what no
reader took can be handed to someone else (an operator's command refused while paused).
"""

from __future__ import annotations

from typing import Any

from engine.blackboard.board import Blackboard
from engine.nodes.event_reader import EventReader, where_they_stand

Place = tuple[int, frozenset[int]]


class TreeEvents:
    """The readers of one built tree (``root``: its root node, found once)."""

    def __init__(self, root: Any, blackboard: Blackboard) -> None:
        self.root = root
        self.blackboard = blackboard
        self.readers: list[EventReader] = [
            node.events
            for node in root.iterate()
            if isinstance(getattr(node, "events", None), EventReader)
        ]
        self._round_start: list[tuple[EventReader, Place]] = []

    def round_starts(self) -> None:
        """A round begins: remember where each reader stands, to try it again from there."""
        self._round_start = [(reader, reader.place()) for reader in self.readers]

    def back_to_round_start(self) -> None:
        """Hand the events of the round cut short back to its readers."""
        for reader, place in self._round_start:
            reader.go_back(place)

    def round_ends(self) -> None:
        """The round is over (done, given up, or halted and let go): an event one reader
        took is the tree's, and no other of its readers reacts to it later."""
        taken: dict[str, list[int]] = {}
        for reader in self.readers:
            if reader.taken:
                taken.setdefault(reader.key, []).extend(reader.taken)
                reader.taken = []
        for reader in self.readers if taken else ():
            reader.passes_over(taken.get(reader.key, ()))

    def unread(self) -> bool:
        """Whether an event came that a reader has not handled yet (a second pat in one
        round, a command that came while another was carried out)."""
        return any(reader.unread() for reader in self.readers)

    def take_unread(self, key: str) -> list[Any]:
        """The values of ``key``'s events that no reader has handled yet, oldest first;
        from now on its readers take them as handled (they are the caller's)."""
        readers = [reader for reader in self.readers if reader.key == key]
        if not any(reader.unread() for reader in readers):  # the usual tick: nothing
            return []
        log = self.blackboard.event_log(key)
        took = {seq for reader in readers for seq in reader.taken}  # this round's
        unread = [
            event
            for event in log.after(min(reader.handled_seq for reader in readers))
            if event.seq not in took and not all(r.done_with(event.seq) for r in readers)
        ]
        for reader in readers:
            reader.handled_seq = max(reader.handled_seq, log.last_seq)
        return [event.value for event in unread]

    def places(self) -> dict[str, Place]:
        """Where a new version of the tree takes up each key (:func:`where_they_stand`)."""
        return where_they_stand(self.readers)

    def take_up(self, places: dict[str, Place]) -> None:
        """Read on from ``places`` (an old version's, from :meth:`places`)."""
        for reader in self.readers:
            if reader.key in places:
                reader.take_up(places[reader.key])
