"""Real people's voices (issue 24): the set reads the same from Debian's packages every
time, and the robot's end-of-turn wait never cuts one of their sentences in two."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine.media.audio import SPEECH_RATE_HZ, Audio
from engine.speech.hearing import utterances
from engine.speech.vad import SileroVad

from .real_voices import (
    SPHINX_DATA,
    RealVoiceClip,
    RealVoicesChangedError,
    missing_real_voices,
    real_voice_set,
)

needs_real_voices = pytest.mark.skipif(
    missing_real_voices() is not None, reason=missing_real_voices() or ""
)


@pytest.fixture(scope="module")
def real_voices() -> list[RealVoiceClip]:
    return real_voice_set()


@needs_real_voices
def test_the_set_is_43_people_saying_one_thing_each_in_under_7_seconds(
    real_voices: list[RealVoiceClip],
) -> None:
    # 5 cards, 2 librivox, goforward (16 kHz); 35 of Allison Smith's prompts (8 kHz)
    assert len(real_voices) == 43
    assert len({clip.name for clip in real_voices}) == 43
    assert [clip.audio.rate_hz for clip in real_voices] == [16000] * 8 + [8000] * 35
    for clip in real_voices:
        speech = clip.audio.resampled(SPEECH_RATE_HZ)
        assert speech.rate_hz == SPEECH_RATE_HZ
        assert 0.8 <= speech.seconds <= 7.0, clip.name
        assert abs(speech.seconds - clip.audio.seconds) < 0.001, clip.name
        assert clip.transcript.strip(), clip.name
        assert clip.audio.samples.std() > 0.01, f"{clip.name} is near silence"


@needs_real_voices
def test_the_end_of_turn_wait_never_cuts_a_real_sentence_in_two(
    real_voices: list[RealVoiceClip], vad: SileroVad
) -> None:
    # each clip is one turn: with the detector's defaults (0.3 s of quiet ends it) the
    # robot hears it as one utterance, which holds every loud part of the clip (the first
    # sound too: Silero hears a word about 80 ms after it starts; the pre-roll keeps it).
    # The longest pause inside a clip is 0.288 s (pbx-invalidpark, between "extension."
    # and "Please try again."): one 32 ms frame short of the wait.
    cut, clipped = [], []
    for clip in real_voices:
        found = utterances(clip.audio, vad)
        spans_s = [
            ((u.end_sample - len(u.audio.samples)) / SPEECH_RATE_HZ, u.end_sample / SPEECH_RATE_HZ)
            for u in found
        ]
        if len(found) != 1:
            cut.append(f"{clip.name}: {[(round(a, 2), round(b, 2)) for a, b in spans_s]} s")
        elif not all(spans_s[0][0] <= at_s <= spans_s[0][1] for at_s in loud_s(clip.audio)):
            clipped.append(f"{clip.name}: {spans_s[0]} s")
    assert cut == [], "cut in two"
    assert clipped == [], "a loud part left out of the utterance"


def loud_s(audio: Audio, below_peak_db: float = 20.0, window_s: float = 0.01) -> list[float]:
    """Where (seconds, each window's start and end) ``audio`` is within ``below_peak_db``
    of its loudest ``window_s``: speech, in a clean recording."""
    width = round(window_s * audio.rate_hz)
    count = len(audio.samples) // width
    rms = np.sqrt((audio.samples[: count * width].reshape(count, width) ** 2).mean(axis=1))
    loud = np.nonzero(rms >= rms.max() * 10 ** (-below_peak_db / 20))[0]
    return [float(i * window_s) for i in loud] + [float((i + 1) * window_s) for i in loud]


def test_a_package_whose_transcript_changed_is_noticed(tmp_path: Path) -> None:
    cards = tmp_path / SPHINX_DATA / "cards"
    cards.mkdir(parents=True)
    (cards / "cards.transcription").write_text(
        "<s> ten of diamonds </s> (001)\n<s> four queen of clubs </s> (002)\n"
    )
    with pytest.raises(RealVoicesChangedError, match="'001' is listed as 'ten of clubs'"):
        real_voice_set(tmp_path)


def test_a_machine_without_the_packages_is_told_which_to_install(tmp_path: Path) -> None:
    assert missing_real_voices(tmp_path) == (
        "the real-voice set needs Debian's pocketsphinx-testdata, asterisk-core-sounds-en-wav"
        " and asterisk-core-sounds-en (scripts/setup installs them)"
    )
