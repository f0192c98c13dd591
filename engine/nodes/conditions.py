"""Conditions: yes/no questions about the blackboard. SUCCESS means yes, FAILURE no."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from engine.blackboard.catalogue import TOUCH_PAT, VARIABLES_PREFIX, KeySpec
from engine.nodes.base import Condition
from engine.nodes.event_reader import EQUALS, ONE_OF, EventReader, check_choice, wanted
from engine.values.param_problems import CheckContext, ParamIssue
from engine.values.params import SECONDS, Integer, Key, ListOf, Number, Param, Scalar, Text

_COMPARISONS = ("equals", "not_equals", "above", "below", "between")
_WORDS_FOR_BOOLEANS = ("true", "false", "yes", "no", "on", "off")
_HOLDS = {"bool": "true/false", "number": "a number", "integer": "a whole number", "text": "text"}


def _mismatch(key: str, spec: KeySpec, value: object) -> tuple[str, str] | None:
    """(message, hint) when ``value`` can never equal a value of ``key``; None when it can."""
    if isinstance(value, float) and math.isnan(value):
        return f"nothing equals {value!r}, not even {key}", "compare with a number"
    if spec.value_type is bool and not isinstance(value, bool):
        word = str(value).strip().lower()
        if word in _WORDS_FOR_BOOLEANS:
            written = "true" if word in ("true", "yes", "on") else "false"
            hint = f"write {written} without quotes"
        else:
            hint = "write true or false, without quotes"
        return f"{key} holds true/false, never {value!r}", hint
    if spec.value_type in (float, int) and (
        isinstance(value, bool) or not isinstance(value, int | float)
    ):
        try:
            hint = f"write {float(str(value)):g} without quotes"
        except ValueError:
            hint = "compare with a number, e.g. equals: 3"
        return f"{key} holds a number, never {value!r}", hint
    if spec.value_type is str and not isinstance(value, str):
        shown = str(value).lower() if isinstance(value, bool) else str(value)
        return f"{key} holds text, never {value!r}", f'put it in quotes: "{shown}"'
    return None


class Check(Condition):
    """Compare a blackboard value: equals, not_equals, above, below or between.

    Give exactly one comparison. ``item`` picks one element of a list value (pad 3 of
    /sensors/touch/pads). SUCCESS when the comparison holds; FAILURE when it does not or
    the key has no value yet.
    """

    key = Param("key", Key(), doc="the blackboard key to look at")
    equals = Param("equals", Scalar(), None, "SUCCESS when the value equals this")
    not_equals = Param("not_equals", Scalar(), None, "SUCCESS when the value differs from this")
    above = Param("above", Number(), None, "SUCCESS when the value is greater than this")
    below = Param("below", Number(), None, "SUCCESS when the value is less than this")
    between = Param(
        "between",
        ListOf(Number(), 2, 2),
        None,
        "[low, high]: SUCCESS when low <= value <= high",
    )
    item = Param("item", Integer(minimum=0), None, "for list values: which element (from 0)")

    @classmethod
    def check_params(cls, args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
        given = [name for name in _COMPARISONS if args.get(name) is not None]
        problems: list[ParamIssue] = []
        if len(given) != 1:
            found = ", ".join(given) if given else "none"
            problems.append(
                ParamIssue(
                    None,
                    f"Check needs exactly one comparison, found {found}",
                    "use one of " + ", ".join(_COMPARISONS),
                )
            )
        between = args.get("between")
        if between is not None and between[0] > between[1]:
            problems.append(
                ParamIssue(
                    "between",
                    f"low {between[0]:g} is above high {between[1]:g}",
                    "write [low, high]",
                )
            )
        spec = ctx.catalogue.lookup(args.get("key", ""))
        numeric = {"above", "below", "between"} & set(given)
        if spec is not None and numeric and spec.value_type in (bool, str, dict):
            problems.append(
                ParamIssue(
                    numeric.pop(),
                    f"{args['key']} holds {spec.type_name}, not a number",
                    "use equals",
                )
            )
        if spec is not None and spec.value_type is list and args.get("item") is None:
            problems.append(
                ParamIssue(
                    "item",
                    f"{args['key']} holds a list: say which item to check",
                    "add item: 0 for the first",
                )
            )
        variable = str(args.get("key", "")).startswith(VARIABLES_PREFIX)
        if spec is not None and not variable:
            if args.get("item") is not None and spec.value_type not in (list, object):
                holds = _HOLDS.get(spec.type_name, "an object")
                problems.append(
                    ParamIssue("item", f"{args['key']} holds {holds}, not a list", "remove item:")
                )
            if spec.value_type is not list:  # a list's items have no declared type
                for name in ("equals", "not_equals"):
                    value = args.get(name)
                    mismatch = _mismatch(args["key"], spec, value) if value is not None else None
                    if mismatch is not None:
                        problems.append(ParamIssue(name, *mismatch))
        return problems

    _test: Callable[[Any], bool]
    """The comparison the parameters ask for, applied to the key's value."""

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self._key = self.key
        self._item = self.item
        if self.equals is not None:
            expected = self.equals
            self._test = lambda value: value == expected
        elif self.not_equals is not None:
            unexpected = self.not_equals
            self._test = lambda value: value != unexpected
        elif self.above is not None:
            threshold = self.above
            self._test = lambda value: value > threshold
        elif self.below is not None:
            threshold = self.below
            self._test = lambda value: value < threshold
        else:
            assert self.between is not None  # check_params: exactly one comparison is given
            low, high = self.between
            self._test = lambda value: low <= value <= high

    def check(self) -> bool:
        value = self.read(self._key)
        if value is not None and self._item is not None:
            if not isinstance(value, list | tuple):  # a /vars/ key may hold anything
                self.feedback_message = f"{self._key} holds {value!r}, not a list"
                return False
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

    key = Param("key", Key(kinds=("state", "event")), doc="the blackboard key")
    within_s = Param("within_s", SECONDS, doc="how recent, in seconds")

    def check(self) -> bool:
        updated = self.ctx.blackboard.updated_s(self.key)
        return updated is not None and self.now() - updated <= self.within_s


class OnEvent(Condition):
    """React once to each new event (a wave, an utterance, a remote command).

    Each tick it takes the oldest event this node has not handled yet. SUCCESS once per
    new event (matching ``equals`` / ``one_of`` when given), writing its value to
    ``save_as``; FAILURE when no new event arrived. Events from before the tree started
    are not reacted to, nor one another node of the tree took in a round that is over (the
    count a game's WaitForEvent took does not start the game again). A key keeps its last
    32 events: when more arrive before this node gets to them, the oldest are missed and
    a warning says how many.
    """

    key = Param("key", Key(kinds=("event",)), doc="the event key, e.g. /sensors/gesture/last")
    equals = EQUALS
    one_of = ONE_OF
    save_as = Param(
        "save_as", Key(access="write"), None, "a /vars/ key to keep the event's value in"
    )

    @classmethod
    def check_params(cls, args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
        return check_choice(args, ctx)

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self.events = EventReader(self, self.key, wanted(self.equals, self.one_of))

    def check(self) -> bool:
        found, value = self.events.take()
        if not found:
            self.feedback_message = ""  # the last event's message would be stale
        elif self.save_as is not None:
            self.write(self.save_as, value)
        return found


class OnTouch(Condition):
    """React once to each new touch of a pad, by the pad's name (a pat).

    A hand coming onto a pad is one pat, however long it rests there. SUCCESS once per
    new pat on one of ``pads`` (any pad when not given) and on none of ``except_pads``,
    writing the pad's name to ``save_as``; FAILURE when no such pat came. Pad names come
    from the robot config's ``pad_names`` (``vest keys --pads`` shows them on the vest).
    """

    pads = Param("pads", ListOf(Text(), 1), None, "only pats on these pads count")
    except_pads = Param("except_pads", ListOf(Text(), 1), None, "pats on these pads do not count")
    save_as = Param("save_as", Key(access="write"), None, "a /vars/ key to keep the pad's name in")
    reads = (TOUCH_PAT,)

    @classmethod
    def check_params(cls, args: Mapping[str, Any], ctx: CheckContext) -> list[ParamIssue]:
        both = set(args.get("pads") or ()) & set(args.get("except_pads") or ())
        if both:
            return [ParamIssue("except_pads", f"{sorted(both)} are in pads and except_pads")]
        return []

    def __init__(self, *a: Any) -> None:
        super().__init__(*a)
        self.events = EventReader(self, TOUCH_PAT, self.pads, self.except_pads or ())

    def check(self) -> bool:
        found, pad = self.events.take()
        if not found:
            self.feedback_message = ""
            return False
        self.feedback_message = f"a pat on {pad}"
        if self.save_as is not None:
            self.write(self.save_as, pad)
        return True


CONDITIONS = (Check, Fresh, OnEvent, OnTouch)
