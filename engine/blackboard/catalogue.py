"""The catalogue of blackboard keys: name, type, unit, writer and meaning.

The YAML loader checks every key a tree names against it (with "did you mean"), the docs
list it, and the catalogue says which keys are *events* (reacted to once per event) rather
than *state* (read every tick). Keys under ``/vars/`` are variables that all trees of a
robot share; ``/devices/<name>/ok`` exists for every configured device.
"""

from __future__ import annotations

import difflib
import fnmatch
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any, Literal

Kind = Literal["state", "event"]

VARIABLES_PREFIX = "/vars/"
SENSORS_PREFIX = "/sensors/"
DEVICES_PREFIX = "/devices/"


# -- every sensor key's name, defined once (the catalogue below describes each) ----------------
TOUCH_PADS = "/sensors/touch/pads"
TOUCH_ANY = "/sensors/touch/any"
TOUCH_TOUCHED = "/sensors/touch/touched"
TOUCH_PAT = "/sensors/touch/pat"
FORCE_SQUEEZE = "/sensors/force/squeeze"
FORCE_LEFT_N = "/sensors/force/left_n"
FORCE_RIGHT_N = "/sensors/force/right_n"
RANGE_LEFT_MM = "/sensors/range/left_mm"
RANGE_CENTER_MM = "/sensors/range/center_mm"
RANGE_RIGHT_MM = "/sensors/range/right_mm"
GESTURE_LAST = "/sensors/gesture/last"
TEMPERATURE_C = "/sensors/temperature/c"
TEMPERATURE_F = "/sensors/temperature/f"
ULTRASOUND_CM = "/sensors/ultrasound/cm"
SPEECH_HEARD = "/speech/heard"
SPEECH_NOT_LISTENED = "/speech/not_listened"
IOT_INBOX = "/iot/inbox"
IOT_CANCELED = "/iot/canceled"
HAND_FINGERS = "/vision/hand/fingers"
HAND_CONFIDENCE = "/vision/hand/confidence"
HAND_SHOWN = "/vision/hand/shown"
HAND_HELD = "/vision/hand/held"
HAND_BOX = "/vision/hand/box"
VISION_PREFIX = "/vision/"
SPEECH_PREFIX = "/speech/"

# -- what of a person a key's value is (the names a consent record covers) --------------------
READINGS = "sensors"
"""A sensor reading or what the camera saw: consent's ``sensors``."""
WORDS = "speech_text"
"""What a person said, as text: consent's ``speech_text``."""
Carries = frozenset[str]
"""What of a person a value holds or was made from: some of :data:`READINGS` and
:data:`WORDS` (empty: nothing of anyone, the robot's own)."""
NOTHING: Carries = frozenset()


def captures_of(key: str) -> Carries:
    """What of a person ``key``'s value is, by where it lives: ``/sensors/`` and
    ``/vision/`` hold readings, ``/speech/`` what was said (but ``not_listened``, which
    holds only when); a tree's ``/vars/`` hold what their writer made them from (the
    blackboard knows: :meth:`~engine.blackboard.board.Blackboard.carried_by`)."""
    if key.startswith((SENSORS_PREFIX, VISION_PREFIX)):
        return _READINGS
    if key.startswith(SPEECH_PREFIX) and key != SPEECH_NOT_LISTENED:
        return _WORDS
    return NOTHING


_READINGS: Carries = frozenset({READINGS})
_WORDS: Carries = frozenset({WORDS})


def force_key(pad: str) -> str:
    """The default key of a force pad: ``/sensors/force/<pad>_n``."""
    return f"/sensors/force/{pad}_n"


def range_key(side: str) -> str:
    """The key of a range sensor looking ``side`` (left, center, right): ``.../<side>_mm``."""
    return f"/sensors/range/{side}_mm"


@dataclass(frozen=True)
class KeySpec:
    """What one blackboard key holds.

    ``name`` may contain one ``*`` segment for families of keys (``/devices/*/ok``).
    ``value_type`` is what a comparison against it must be: bool, float (int accepted),
    str, list (of the item type) or object. ``alias`` is a short name for text templates
    (``{temperature_f:.0f}``).
    """

    name: str
    value_type: type
    unit: str
    writer: str
    description: str
    kind: Kind = "state"
    alias: str | None = None

    @property
    def is_pattern(self) -> bool:
        return "*" in self.name

    def matches(self, key: str) -> bool:
        if not self.is_pattern:
            return key == self.name
        return fnmatch.fnmatchcase(key, self.name) and key.count("/") == self.name.count("/")

    @property
    def type_name(self) -> str:
        return {bool: "bool", float: "number", int: "integer", str: "text", list: "list"}.get(
            self.value_type, "object"
        )


VARIABLE_SPEC = KeySpec(
    VARIABLES_PREFIX + "*",
    object,
    "",
    "trees",
    "a variable shared by every tree of the robot (any value; name it after the tree that "
    "writes it)",
)


class KeyCatalogue:
    """A set of :class:`KeySpec`; look up a key, list them, suggest the nearest."""

    def __init__(self, specs: Iterable[KeySpec]) -> None:
        self._exact: dict[str, KeySpec] = {}
        self._patterns: list[KeySpec] = []
        for spec in specs:
            self.add(spec)

    def add(self, spec: KeySpec) -> None:
        if not spec.name.startswith("/"):
            raise ValueError(f"blackboard keys are absolute: {spec.name!r} must start with '/'")
        if spec.is_pattern:
            self._patterns.append(spec)
        else:
            self._exact[spec.name] = spec

    def lookup(self, key: str) -> KeySpec | None:
        """The spec of ``key``; tree variables (``/vars/...``) always exist."""
        spec = self._exact.get(key)
        if spec is not None:
            return spec
        if key.startswith(VARIABLES_PREFIX) and len(key) > len(VARIABLES_PREFIX):
            return VARIABLE_SPEC
        for pattern in self._patterns:
            if pattern.matches(key):
                return pattern
        return None

    def by_alias(self, alias: str) -> KeySpec | None:
        for spec in self._exact.values():
            if spec.alias == alias:
                return spec
        return None

    def suggest(self, key: str) -> str | None:
        """The known key nearest to ``key``, or None when nothing is close."""
        names = [*self._exact, *(p.name for p in self._patterns)]
        close = difflib.get_close_matches(key, names, n=1, cutoff=0.6)
        return close[0] if close else None

    def __iter__(self) -> Iterator[KeySpec]:
        yield from sorted(self._exact.values(), key=lambda s: s.name)
        yield from self._patterns
        yield VARIABLE_SPEC

    def __contains__(self, key: Any) -> bool:
        return isinstance(key, str) and self.lookup(key) is not None


def default_catalogue() -> KeyCatalogue:
    """The keys every vest robot has."""
    return KeyCatalogue(
        [
            KeySpec(
                TOUCH_PADS,
                list,
                "",
                "touch poller (MPR121)",
                "12 booleans, True while that pad is touched",
            ),
            KeySpec(
                TOUCH_ANY,
                bool,
                "",
                "touch poller (MPR121)",
                "True while any pad is touched",
            ),
            KeySpec(
                TOUCH_TOUCHED,
                list,
                "",
                "touch poller (MPR121)",
                "the names of the pads touched now (the robot config's pad_names)",
            ),
            KeySpec(
                TOUCH_PAT,
                str,
                "",
                "touch poller (MPR121)",
                "a pad's name, once each time a hand comes onto it (a resting hand is one pat)",
                kind="event",
            ),
            KeySpec(
                FORCE_SQUEEZE,
                str,
                "",
                "force poller (ADS1115 / MCP3008 + FSR 406)",
                "a force pad's name (left, right), once each time it is squeezed past the "
                "config's squeeze_n",
                kind="event",
            ),
            KeySpec(
                FORCE_LEFT_N,
                float,
                "N",
                "force poller (ADS1115 + FSR 406)",
                "force on the left side pad",
                alias="force_left_n",
            ),
            KeySpec(
                FORCE_RIGHT_N,
                float,
                "N",
                "force poller (ADS1115 + FSR 406)",
                "force on the right side pad",
                alias="force_right_n",
            ),
            KeySpec(
                RANGE_LEFT_MM,
                float,
                "mm",
                "range poller (VL53L0X)",
                "distance seen by the left time-of-flight sensor; absent when nothing is in range",
                alias="range_left_mm",
            ),
            KeySpec(
                RANGE_CENTER_MM,
                float,
                "mm",
                "range poller (VL53L0X)",
                "distance seen by the center time-of-flight sensor",
                alias="range_center_mm",
            ),
            KeySpec(
                RANGE_RIGHT_MM,
                float,
                "mm",
                "range poller (VL53L0X)",
                "distance seen by the right time-of-flight sensor",
                alias="range_right_mm",
            ),
            KeySpec(
                GESTURE_LAST,
                str,
                "",
                "gesture poller (ZX sensor)",
                "a hand gesture: wave, swipe_left, swipe_right, swipe_up, hover, ...",
                kind="event",
            ),
            KeySpec(
                TEMPERATURE_C,
                float,
                "degC",
                "temperature service (MCP9808)",
                "room temperature, read on request",
                alias="temperature_c",
            ),
            KeySpec(
                TEMPERATURE_F,
                float,
                "degF",
                "temperature service (MCP9808)",
                "room temperature, read on request",
                alias="temperature_f",
            ),
            KeySpec(
                ULTRASOUND_CM,
                float,
                "cm",
                "ultrasound service (SRF02)",
                "distance in front of the robot, read on request",
                alias="ultrasound_cm",
            ),
            KeySpec(
                SPEECH_HEARD,
                str,
                "",
                "speech recognizer",
                "an utterance the robot heard, as text",
                kind="event",
            ),
            KeySpec(
                SPEECH_NOT_LISTENED,
                dict,
                "",
                "speech listener",
                "someone spoke while the robot was speaking and was not listened to: "
                "{from_s, until_s, why} (clock seconds)",
                kind="event",
            ),
            KeySpec(
                IOT_INBOX,
                dict,
                "",
                "IoT client",
                "a remote command: {id, type, args}",
                kind="event",
            ),
            KeySpec(
                IOT_CANCELED,
                str,
                "",
                "IoT client",
                "the id of a remote command the operator canceled while the robot carried "
                "it out (the tree carrying it out stops)",
                kind="event",
            ),
            KeySpec(
                HAND_FINGERS,
                int,
                "",
                "vision worker (camera + hand finder)",
                "fingers the hand held up in the camera's view shows, 0..5; absent when no "
                "hand is held up or its count is not sure",
                alias="hand_fingers",
            ),
            KeySpec(
                HAND_CONFIDENCE,
                float,
                "",
                "vision worker (camera + hand finder)",
                "how sure the finder is of the newest frame's hand, 0..1",
                alias="hand_confidence",
            ),
            KeySpec(
                HAND_BOX,
                dict,
                "px",
                "vision worker (camera + hand finder)",
                "where the hand held up is in the camera's frame: {x, y, width, height, "
                "frame_width, frame_height} px; absent when no hand is held up",
            ),
            KeySpec(
                HAND_SHOWN,
                int,
                "",
                "vision worker (camera + hand finder)",
                "a hand showing this many fingers, 0..5: once when the count changes and "
                "holds for the camera's steady_frames",
                kind="event",
            ),
            KeySpec(
                HAND_HELD,
                int,
                "",
                "vision worker (camera + hand finder)",
                "the count a hand holds up steadily now, 0..5 (the last /vision/hand/shown); "
                "absent once no hand (or no sure count) has held as long",
                alias="hand_held",
            ),
            KeySpec(
                "/devices/*/ok",
                bool,
                "",
                "bus managers",
                "False while that device is offline (unplugged or failing)",
            ),
        ]
    )
