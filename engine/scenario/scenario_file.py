"""Scenario files: a timeline of what happens around the robot.

::

    duration_s: 20
    events:
      - {at: 1.0,  touch: {pad: middle_back, seconds: 0.3}}   # or a number: pad: 3
      - {at: 3.0,  squeeze: {left_n: 6.0, right_n: 6.0, seconds: 2.0}}
      - {at: 6.0,  gesture: wave}
      - {at: 8.0,  obstacle: {left_mm: 250, center_mm: 600, right_mm: 900, seconds: 2.0}}
      - {at: 10.0, temperature: {c: 22.2}}
      - {at: 11.0, hear: "what is the temperature"}
      - {at: 12.5, hear: {text: "what is your name", snr_db: 10}}   # in a noisy room
      - {at: 13.5, hear: {wav: recordings/question.wav}}             # beside the scenario
      - {at: 14.0, cloud: {type: say, args: {text: "hello from the cloud"}}}
      - {at: 14.5, press: Well done}     # a button of the file given with --buttons
      - {at: 15.0, show_hand: {fingers: 3, seconds: 2}}   # to the simulated camera
      - {at: 18.0, show_hand: {image: pictures/two.png}}  # beside the scenario
      - {at: 21.0, show_hand: {video: clips/counting.avi}}
      - {at: 0.0,  echo: {gain_db: 0, rt60_s: 0.6}}  # how the robot hears itself (or on: false)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from engine.blackboard.catalogue import default_catalogue
from engine.files.fields import converted, settings
from engine.files.problems import LoadError, Mark, Problems
from engine.files.yaml_source import YList, YMap, YValue, describe, load_yaml
from engine.media.audio import AudioFileError, read_wav
from engine.scenario.event_fields import EVENT_FIELDS
from engine.values.param_problems import CheckContext, did_you_mean
from engine.values.params import SECONDS, Number, ParamType, Text


@dataclass(frozen=True)
class ScenarioEvent:
    at_s: float
    kind: str
    value: Any
    mark: Mark

    def describe(self) -> str:
        """A short human description for the timeline."""
        value = self.value
        if self.kind == "touch":
            pad = value.get("pad_name") or f"pad {value['pad']}"
            return f"{pad} touched for {value['seconds']:g} s"
        if self.kind == "squeeze":
            return (
                f"squeezed left {value['left_n']:g} N, right {value['right_n']:g} N "
                f"for {value['seconds']:g} s"
            )
        if self.kind == "obstacle":
            seen = ", ".join(
                f"{side} {value[side + '_mm']:g} mm"
                for side in ("left", "center", "right")
                if value[side + "_mm"] is not None
            )
            return f"obstacle at {seen or 'nothing'} for {value['seconds']:g} s"
        if self.kind == "temperature":
            return f"room at {value['c']:.1f} degC"
        if self.kind == "ultrasound":
            return f"object {value['cm']:g} cm ahead for {value['seconds']:g} s"
        if self.kind == "unplug":
            return f"{value['device']} unplugged for {value['seconds']:g} s"
        if self.kind == "fault":
            return f"{value['device']}: {value['kind']} for {value['seconds']:g} s"
        if self.kind == "hear":
            said = repr(value["text"]) if value["text"] is not None else value["wav"]
            noise = f" at {value['snr_db']:g} dB SNR" if value["snr_db"] is not None else ""
            return f"someone says {said}{noise}"
        if self.kind == "show_hand":
            if value["fingers"] is not None:
                count = value["fingers"]
                shown = f"a hand showing {count} finger{'' if count == 1 else 's'}"
            else:
                shown = Path(value["image"] or value["video"]).name
            return f"{shown} in front of the camera for {value['seconds']:g} s"
        if self.kind == "cloud":
            args = ", ".join(f"{name} {_word(v)}" for name, v in (value["args"] or {}).items())
            return f"operator sends {value['type']}" + (f": {args}" if args else "")
        if self.kind == "press":
            return f"presses the button {value!r}"
        if self.kind == "button":
            return f"presses the button {value['label']!r}"
        return f"{self.kind} {value}"


def _word(value: Any) -> str:
    """A command's argument as a person reads it: text in quotes, numbers as they are."""
    if isinstance(value, str):
        return f'"{value}"'
    return f"{value:g}" if isinstance(value, float) else str(value)


@dataclass(frozen=True)
class Scenario:
    duration_s: float
    events: tuple[ScenarioEvent, ...]
    path: Path


def load_scenario(path: Path, shown: str | None = None) -> Scenario:
    """Read and validate a scenario; LoadError with every problem."""
    name = shown or str(path)
    return check_scenario(load_yaml(path, name), name, path)


def check_scenario(document: YValue | None, name: str, path: Path) -> Scenario:
    problems = Problems()
    if not isinstance(document, YMap):
        problems.add(
            document.mark if document else Mark(name, 1, 1),
            "a scenario is a mapping with 'duration_s:' and 'events:'",
        )
        problems.raise_if_any()
    assert isinstance(document, YMap)
    problems.unknown_fields(document.key_marks, ("duration_s", "events", "description"), "scenario")
    ctx = CheckContext(default_catalogue())
    duration = 0.0
    raw_duration = document.get("duration_s")
    if raw_duration is None:
        problems.add(document.mark, "a scenario needs 'duration_s:'", "seconds, e.g. 20")
    else:
        duration = (
            converted(Number(0.01, 24 * 3600.0, "s"), raw_duration, "duration_s", ctx, problems)
            or 0.0
        )
    events: list[ScenarioEvent] = []
    raw_events = document.get("events")
    if raw_events is not None and not isinstance(raw_events, YList):
        problems.add(raw_events.mark, f"'events' must be a list, got {describe(raw_events)}")
    elif raw_events is not None:
        for index, raw in enumerate(raw_events):
            event = scenario_event(raw, ctx, problems, index, path.parent)
            if event is None:
                continue
            if duration and event.at_s > duration:
                problems.add(
                    raw.mark,
                    f"event at {event.at_s:g} s is after the scenario ends ({duration:g} s)",
                    "raise duration_s",
                )
            events.append(event)
    problems.raise_if_any()
    events.sort(key=lambda e: e.at_s)
    return Scenario(duration, tuple(events), path)


def scenario_event(
    raw: YValue, ctx: CheckContext, problems: Problems, index: int, folder: Path
) -> ScenarioEvent | None:
    """One event of a scenario's ``events:`` (the ``index``-th), or None after adding its
    problems; files it names are relative to ``folder``."""
    if not isinstance(raw, YMap):
        problems.add(raw.mark, "an event is a mapping like {at: 1.0, touch: {pad: 3}}")
        return None
    kinds = [key for key in raw.entries if key != "at"]
    at = raw.get("at")
    at_s = None
    if at is None:
        problems.add(raw.mark, "event has no 'at:'", "seconds from the start, e.g. at: 1.5")
    else:
        at_s = converted(SECONDS, at, "at", ctx, problems)
    if len(kinds) != 1:
        problems.add(
            raw.mark,
            f"an event has 'at' and one kind, got {len(kinds)} kinds",
            "kinds: " + ", ".join(EVENT_FIELDS),
        )
        return None
    kind = kinds[0]
    fields = EVENT_FIELDS.get(kind)
    if fields is None:
        problems.add(
            raw.key_marks[kind],
            f"unknown event {kind!r}",
            did_you_mean(kind, list(EVENT_FIELDS)) or "kinds: " + ", ".join(EVENT_FIELDS),
        )
        return None
    body = raw.entries[kind]
    if kind == "hear" and not isinstance(body, YMap):  # hear: "text" is hear: {text: ...}
        text = converted(Text(), body, kind, ctx, problems)
        value = None if text is None else {"text": text, "wav": None, "snr_db": None}
    elif isinstance(fields, ParamType):
        value = converted(fields, body, kind, ctx, problems)
    else:
        value = settings(body, fields, kind, ctx, problems)
    if value is None or at_s is None:
        return None
    if kind == "temperature":
        if (value["c"] is None) == (value["f"] is None):
            problems.add(body.mark, "temperature takes c or f", "e.g. {c: 22.2}")
            return None
        if value["c"] is None:
            value["c"] = (value["f"] - 32.0) * 5.0 / 9.0
    if kind == "hear" and not _check_hearing(value, body, folder, problems):
        return None
    if kind == "show_hand" and not _check_showing(value, body, folder, problems):
        return None
    if kind == "cloud":
        if value["args"] is not None and not isinstance(value["args"], dict):
            problems.add(body.mark, "cloud 'args' must be a mapping", "e.g. {text: hello}")
            return None
        value["id"] = value["id"] or f"cmd-{index + 1}"
    return ScenarioEvent(float(at_s), kind, value, raw.mark)


def _check_hearing(value: dict[str, Any], body: YValue, folder: Path, problems: Problems) -> bool:
    """Text (with words), a wav, or both (the wav is then what the text says: the timeline
    shows the text, the microphone hears the recording); a wav that is a WAV file we can
    use (read now, so a bad one is named before the run), made absolute."""
    if value["text"] is None and value["wav"] is None:
        problems.add(
            body.mark, "hear takes text, wav or both", "e.g. {text: hello} or {wav: question.wav}"
        )
        return False
    if value["text"] is not None and not any(c.isalnum() for c in value["text"]):
        problems.add(body.mark, "hear has no words to say", "write what the person says")
        return False
    if value["wav"] is not None:
        wav = folder / value["wav"]
        try:
            read_wav(wav)
        except LoadError as error:
            why = error.problems[0].message
            problems.add(body.mark, f"{wav}: {why}", "a path relative to the scenario file")
            return False
        except AudioFileError as error:
            problems.add(body.mark, str(error), "a 16-bit PCM WAV file works everywhere")
            return False
        value["wav"] = str(wav)
    return True


def _check_showing(value: dict[str, Any], body: YValue, folder: Path, problems: Problems) -> bool:
    """Exactly one of fingers, image and video; a picture or video that OpenCV reads (now,
    so a bad one is named before the run), made absolute."""
    given = [name for name in ("fingers", "image", "video") if value[name] is not None]
    if len(given) != 1:
        problems.add(
            body.mark,
            "show_hand takes one of fingers, image and video",
            "e.g. {fingers: 3} or {image: two_fingers.png}",
        )
        return False
    if given[0] == "fingers":
        if value["at"] is not None or value["width_px"] is not None:
            problems.add(body.mark, "at and width_px place a picture", "give image: as well")
            return False
        return True
    if (value["at"] is None) != (value["width_px"] is None):
        problems.add(
            body.mark,
            "at and width_px go together: where the picture is held, and how big it looks",
            "e.g. {image: hand.jpg, at: [300, 120], width_px: 110}",
        )
        return False
    from engine.media.media_check import check_media  # OpenCV: only for scenarios that need it

    path = folder / value[given[0]]
    why = check_media(path, video=given[0] == "video")
    if why is not None:
        problems.add(body.mark, why, "a path relative to the scenario file")
        return False
    value[given[0]] = str(path)
    return True
