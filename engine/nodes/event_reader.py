"""Reading one event key in order, for the nodes that react to events (OnEvent, WaitForEvent)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from engine.blackboard.events import EVENT_LOG_LENGTH, EventLog
from engine.nodes.base import Leaf, node_path
from engine.values.param_problems import CheckContext, ParamIssue
from engine.values.params import ListOf, Param, Scalar

EQUALS = Param("equals", Scalar(), None, "only events with this value count")
ONE_OF = Param("one_of", ListOf(Scalar(), 1), None, "only events with one of these values count")
"""The parameters that choose which events count (OnEvent, WaitForEvent)."""


def check_choice(args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
    """``equals`` and ``one_of`` are one or the other."""
    if args.get("equals") is not None and args.get("one_of") is not None:
        return [ParamIssue("one_of", "give equals or one_of, not both")]
    return []


def wanted(equals: Any, one_of: Sequence[Any] | None) -> list[Any] | None:
    """The event values that count (None: every one)."""
    if one_of:
        return list(one_of)
    return None if equals is None else [equals]


class EventReader:
    """The events on ``key`` a node has not handled yet, oldest first; those matching
    ``wanted`` (any, when None) count. A key keeps its last 32 events: when more arrive
    before the node reads them, the oldest are missed and the node warns how many.

    An event another node of the tree took in a round that has ended is passed over
    (:meth:`passes_over`): a hand count the game's inner wait took does not start the game
    again at its root."""

    def __init__(
        self,
        node: Leaf,
        key: str,
        wanted: Sequence[Any] | None,
        unwanted: Sequence[Any] = (),
    ) -> None:
        self.node, self.key = node, key
        self.wanted = None if wanted is None else list(wanted)
        self.unwanted = list(unwanted)
        """Values that never count (a pat on a pad the node leaves to others)."""
        self.handled_seq = 0
        self.taken: list[int] = []
        """The events that counted this round (their numbers)."""
        self._passed_over: set[int] = set()
        self.skip_past()

    def passes_over(self, seqs: Sequence[int]) -> None:
        """Those of ``seqs`` (event numbers) this node has not handled yet are not for it."""
        self._passed_over.update(seq for seq in seqs if seq > self.handled_seq)

    def done_with(self, seq: int) -> bool:
        """Whether event ``seq`` is behind this node, or one it passes over."""
        return seq <= self.handled_seq or seq in self._passed_over

    def place(self) -> tuple[int, frozenset[int]]:
        """Where it stands, to come back to (:meth:`go_back`: a round tried again)."""
        return self.handled_seq, frozenset(self._passed_over)

    def go_back(self, place: tuple[int, frozenset[int]]) -> None:
        """Read again from ``place`` (never forward: what it read since stays read when
        ``place`` is ahead); what it took this round is taken again."""
        seq, passed = place
        if seq < self.handled_seq:
            self.handled_seq, self._passed_over = seq, set(passed) | self._passed_over
        self.taken = []

    def skip_past(self) -> None:
        """Forget the events already on the key: only later ones count."""
        self.handled_seq = self.node.ctx.blackboard.event_log(self.key).last_seq

    def take_up(self, place: tuple[int, frozenset[int]]) -> None:
        """Read on from ``place``, as the old version of this node's tree stood (a reload)."""
        self.handled_seq, self._passed_over = place[0], set(place[1])
        self.taken = []

    def unread(self) -> bool:
        """Whether events came on the key that this node has not looked at yet."""
        last = self.node.ctx.blackboard.event_log(self.key).last_seq
        if last - self.handled_seq > len(self._passed_over):
            return True
        return any(seq not in self._passed_over for seq in range(self.handled_seq + 1, last + 1))

    def take(self) -> tuple[bool, Any]:
        """(True, value) of the oldest new event that counts, or (False, None)."""
        log = self.node.read(self.key)
        if not isinstance(log, EventLog) or log.last_seq <= self.handled_seq:
            return False, None
        events = log.after(self.handled_seq)
        gone = range(self.handled_seq + 1, events[0].seq) if events else range(0)
        missed = sum(seq not in self._passed_over for seq in gone)  # not ones it passes over
        if missed > 0:
            self.node.ctx.on_node_warning(
                self.node.ctx.tree,
                node_path(self.node),
                f"missed {missed} event{'s' if missed != 1 else ''} on {self.key}: "
                f"more than the {EVENT_LOG_LENGTH} a key keeps came before this node read them",
            )
        found: tuple[bool, Any] = (False, None)
        for event in events:
            self.handled_seq = event.seq
            if event.seq in self._passed_over:
                continue
            if (self.wanted is None or event.value in self.wanted) and (
                event.value not in self.unwanted
            ):
                self.node.feedback_message = f"event {event.seq}: {event.value!r}"
                self.taken = [*self.taken[-EVENT_LOG_LENGTH:], event.seq]  # older: gone anyway
                found = (True, event.value)
                break
        self._passed_over = {seq for seq in self._passed_over if seq > self.handled_seq}
        return found


def where_they_stand(readers: Sequence[EventReader]) -> dict[str, tuple[int, frozenset[int]]]:
    """Each key's place (:meth:`EventReader.place`) for a new version of their tree: the
    slowest of ``readers``' event number, and every event one of them passes over beyond it
    (the tree took it in a round that is over)."""
    places: dict[str, tuple[int, frozenset[int]]] = {}
    for reader in readers:
        seq, passed = reader.place()
        before, passed_before = places.get(reader.key, (seq, frozenset()))
        places[reader.key] = (min(seq, before), passed | passed_before)
    return {
        key: (seq, frozenset(n for n in passed if n > seq)) for key, (seq, passed) in places.items()
    }
