"""The ``audio:`` section of a robot config: the ALSA microphone and speaker."""

from __future__ import annotations

from engine.files.yaml_source import YMap
from engine.hardware.chips.fields import ConfigChecks
from engine.hardware.config import AudioConfig
from engine.values.params import Text


def check_audio(checker: ConfigChecks, document: YMap, simulated: bool) -> AudioConfig:
    """The ALSA devices: ``default`` on a robot; none on the simulated vest (its room
    carries the sound) unless named. ``none`` names no device."""
    default = AudioConfig.for_simulation() if simulated else AudioConfig()
    audio = checker.mapping(
        document.get("audio"), "'audio'", "e.g. audio: {microphone: default, speaker: default}"
    )
    if audio is None:
        return default
    checker.unknown_fields(audio, ("microphone", "speaker"), "audio")
    found: dict[str, str | None] = {}
    for field in ("microphone", "speaker"):
        if field not in audio:
            found[field] = getattr(default, field)
            continue
        name = checker.convert(Text(), audio.entries[field], field)
        if name is not None and (not name.strip() or name != name.strip()):
            checker.problems.add(
                audio.entries[field].mark,
                f"{field} {name!r} is not an ALSA device name",
                "e.g. default, plughw:1,0 or none",
            )
            name = None
        found[field] = None if name in (None, "none") else name
    return AudioConfig(microphone=found["microphone"], speaker=found["speaker"])
