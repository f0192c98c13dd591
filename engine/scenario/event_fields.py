"""What each kind of event a scenario file holds takes: its fields, their units and
ranges, as :mod:`engine.scenario.scenario_file` checks them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from engine.values.param_problems import CheckContext
from engine.values.params import (
    REQUIRED,
    AnyValue,
    Boolean,
    Choice,
    Integer,
    ListOf,
    Number,
    Param,
    ParamType,
    Text,
)

GESTURES = (
    "wave",
    "swipe_left",
    "swipe_right",
    "swipe_up",
    "hover",
    "hover_left",
    "hover_right",
    "hover_up",
)
_SECONDS = Number(0.01, 3600.0, "s")


@dataclass(frozen=True)
class PadRef(ParamType[int | str]):
    """A touch pad by number (0..11) or by the name the robot config gives it; names are
    checked against the robot the scenario runs on."""

    name = "pad"

    def convert(self, value: Any, ctx: CheckContext) -> int | str:
        if isinstance(value, str) and value:
            return value
        return Integer(0, 11).convert(value, ctx)

    def describe(self) -> str:
        return "pad name or number 0..11"

    def json_schema(self) -> dict[str, Any]:
        return {"type": ["string", "integer"]}


_DISTANCE_MM = Number(0.0, 8190.0, "mm")

EVENT_FIELDS: dict[str, tuple[Param[Any], ...] | ParamType[Any]] = {
    "touch": (
        Param("pad", PadRef(), doc="pad name (the robot config's pad_names) or number 0..11"),
        Param("seconds", _SECONDS, 0.3, "how long the hand stays"),
    ),
    "squeeze": (
        Param("left_n", Number(0.0, 100.0, "N"), 0.0, "force on the left side"),
        Param("right_n", Number(0.0, 100.0, "N"), 0.0, "force on the right side"),
        Param("seconds", _SECONDS, 1.0, "how long"),
    ),
    "gesture": Choice(GESTURES),
    "obstacle": (
        Param("left_mm", _DISTANCE_MM, None, "distance seen on the left"),
        Param("center_mm", _DISTANCE_MM, None, "distance seen in the center"),
        Param("right_mm", _DISTANCE_MM, None, "distance seen on the right"),
        Param("seconds", _SECONDS, 2.0, "how long it stays"),
    ),
    "temperature": (
        Param("c", Number(-40.0, 125.0, "degC"), None, "degrees Celsius"),
        Param("f", Number(-40.0, 257.0, "degF"), None, "degrees Fahrenheit"),
    ),
    "ultrasound": (
        Param("cm", Number(0.0, 600.0, "cm"), REQUIRED, "distance of the object"),
        Param("seconds", _SECONDS, 5.0, "how long it stays"),
    ),
    "hear": (
        Param("text", Text(), None, "what is said, spoken by the robot's TTS voice"),
        Param(
            "wav",
            Text(),
            None,
            "a WAV recording of it (relative to the scenario file); with text, the recording "
            "of that text: the same sound on every machine",
        ),
        Param("snr_db", Number(-10.0, 60.0, "dB"), None, "white noise this far below the speech"),
    ),
    "unplug": (
        Param("device", Text(), REQUIRED, "a device of the robot config"),
        Param("seconds", _SECONDS, 3.0, "how long it stays unplugged"),
    ),
    "fault": (
        Param("device", Text(), REQUIRED, "a device of the robot config"),
        Param(
            "kind", Choice(("nack", "unplugged", "garbage", "hold")), REQUIRED, "what goes wrong"
        ),
        Param("seconds", _SECONDS, 1.0, "how long"),
    ),
    "show_hand": (
        Param("fingers", Integer(0, 5), None, "a person holding up 1..5 fingers (0: a fist)"),
        Param("image", Text(), None, "a picture (relative to the scenario file)"),
        Param("video", Text(), None, "a video, played from this moment"),
        Param("seconds", _SECONDS, 2.0, "how long it is held in front of the camera"),
        Param("at", ListOf(Integer(0, 10_000), 2, 2), None, "a picture held at [x, y] px"),
        Param("width_px", Integer(8, 10_000), None, "how wide it looks there, px"),
    ),
    "press": Text(),
    "echo": (
        Param("on", Boolean(), True, "whether the microphone hears the robot's voice at all"),
        Param("delay_s", Number(0.0, 0.5, "s"), 0.012, "from the speaker to the microphone"),
        Param("gain_db", Number(-60.0, 20.0, "dB"), -6.0, "its loudness against what is played"),
        Param("rt60_s", Number(0.0, 2.0, "s"), 0.35, "the room's reverberation time"),
        Param("distortion", Number(0.0, 1.0), 0.3, "the speaker's (0: none, 1: driven hard)"),
    ),
    "cloud": (
        Param("type", Text(), REQUIRED, "command type: say, led, move, read"),
        Param("args", AnyValue(), None, "the command's arguments"),
        Param("id", Text(), None, "command id (default: cmd-N)"),
    ),
}
