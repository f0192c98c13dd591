"""Conditions: yes/no questions about the blackboard. SUCCESS means yes, FAILURE no."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from engine.blackboard.events import EventLog
from engine.nodes.base import Condition
from engine.nodes.params import CheckContext, Integer, Key, ListOf, Number, Param, Scalar

_COMPARISONS = ("equals", "not_equals", "above", "below", "between")


class Check(Condition):
    """Compare a blackboard value: equals, not_equals, above, below or between.

    Give exactly one comparison. ``item`` picks one element of a list value (pad 3 of
    /sensors/touch/pads). SUCCESS when the comparison holds; FAILURE when it does not or
    the key has no value yet.
    """

    params: ClassVar = (
        Param("key", Key(), doc="the blackboard key to look at"),
        Param("equals", Scalar(), None, "SUCCESS when the value equals this"),
        Param("not_equals", Scalar(), None, "SUCCESS when the value differs from this"),
        Param("above", Number(), None, "SUCCESS when the value is greater than this"),
        Param("below", Number(), None, "SUCCESS when the value is less than this"),
        Param(
            "between",
            ListOf(Number(), 2, 2),
            None,
            "[low, high]: SUCCESS when low <= value <= high",
        ),
        Param("item", Integer(minimum=0), None, "for list values: which element (from 0)"),
    )

    @classmethod
    def check_params(
        cls, args: Mapping[str, Any], ctx: CheckContext
    ) -> list[tuple[str | None, str, str | None]]:
        given = [name for name in _COMPARISONS if args.get(name) is not None]
        problems: list[tuple[str | None, str, str | None]] = []
        if len(given) != 1:
            found = ", ".join(given) if given else "none"
            problems.append(
                (
                    None,
                    f"Check needs exactly one comparison, found {found}",
                    "use one of " + ", ".join(_COMPARISONS),
                )
            )
        between = args.get("between")
        if between is not None and between[0] > between[1]:
            problems.append(
                ("between", f"low {between[0]:g} is above high {between[1]:g}", "write [low, high]")
            )
        spec = ctx.catalogue.lookup(args.get("key", ""))
        numeric = {"above", "below", "between"} & set(given)
        if spec is not None and numeric and spec.value_type in (bool, str, dict):
            problems.append(
                (numeric.pop(), f"{args['key']} holds {spec.type_name}, not a number", "use equals")
            )
        if spec is not None and spec.value_type is list and args.get("item") is None:
            problems.append(
                (
                    "item",
                    f"{args['key']} holds a list: say which item to check",
                    "add item: 0 for the first",
                )
            )
        return problems

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        args = self.args
        self._key = args.key
        self._item = args.item
        if args.equals is not None:
            expected = args.equals
            self._test = lambda value: value == expected
        elif args.not_equals is not None:
            unexpected = args.not_equals
            self._test = lambda value: value != unexpected
        elif args.above is not None:
            threshold = args.above
            self._test = lambda value: value > threshold
        elif args.below is not None:
            threshold = args.below
            self._test = lambda value: value < threshold
        else:
            low, high = args.between
            self._test = lambda value: low <= value <= high

    def check(self) -> bool:
        value = self.read(self._key)
        if value is not None and self._item is not None:
            value = value[self._item] if self._item < len(value) else None
        if value is None:
            self.feedback_message = f"{self._key} has no value yet"
            return False
        return bool(self._test(value))


class Fresh(Condition):
    """Is a key's value recent? For sensors that may stop reporting.

    SUCCESS when ``key`` was written within the last ``within_s`` seconds; FAILURE when
    it is older or was never written.
    """

    params: ClassVar = (
        Param("key", Key(kinds=("state", "event")), doc="the blackboard key"),
        Param("within_s", Number(minimum=0.0, unit="s"), doc="how recent, in seconds"),
    )

    def check(self) -> bool:
        updated = self.ctx.blackboard.updated_s(self.args.key)
        return updated is not None and self.now() - updated <= self.args.within_s


class OnEvent(Condition):
    """React once to each new event (a wave, an utterance, a remote command).

    Each tick it takes the oldest event this node has not handled yet. SUCCESS once per
    new event (matching ``equals`` / ``one_of`` when given), writing its value to
    ``save_as``; FAILURE when no new event arrived. Events from before the tree started
    are not reacted to.
    """

    params: ClassVar = (
        Param("key", Key(kinds=("event",)), doc="the event key, e.g. /sensors/gesture/last"),
        Param("equals", Scalar(), None, "only events with this value count"),
        Param("one_of", ListOf(Scalar(), 1), None, "only events with one of these values count"),
        Param("save_as", Key(access="write"), None, "a /vars/ key to keep the event's value in"),
    )

    @classmethod
    def check_params(
        cls, args: Mapping[str, Any], ctx: CheckContext
    ) -> list[tuple[str | None, str, str | None]]:
        if args.get("equals") is not None and args.get("one_of") is not None:
            return [("one_of", "give equals or one_of, not both", None)]
        return []

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self.handled_seq = self.ctx.blackboard.event_log(self.args.key).last_seq
        wanted = self.args.one_of or ([self.args.equals] if self.args.equals is not None else None)
        self._wanted = None if wanted is None else list(wanted)

    def check(self) -> bool:
        log = self.read(self.args.key)
        if not isinstance(log, EventLog) or log.last_seq <= self.handled_seq:
            return False
        for event in log.after(self.handled_seq):
            self.handled_seq = event.seq
            if self._wanted is None or event.value in self._wanted:
                if self.args.save_as is not None:
                    self.write(self.args.save_as, event.value)
                self.feedback_message = f"event {event.seq}: {event.value!r}"
                return True
        return False


CONDITIONS = (Check, Fresh, OnEvent)
