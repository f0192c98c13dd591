"""Silero VAD cuts a noisy stream into utterances; noise alone is no utterance."""

from __future__ import annotations

from collections.abc import Callable

from engine.media.audio import SPEECH_RATE_HZ, Audio, noise, with_noise
from engine.speech.vad import FRAME_S, FRAME_SAMPLES, SileroVad, SpeechDetector


def stream(*parts: Audio) -> Audio:
    audio = parts[0].resampled(SPEECH_RATE_HZ)
    for part in parts[1:]:
        audio = audio.then(part)
    return audio


def test_two_questions_a_second_apart_in_10_db_noise_are_two_utterances(
    spoken: Callable[..., Audio], vad: SileroVad
) -> None:
    question = spoken("what is your name")
    audio = with_noise(stream(question, Audio.silence(1.0), question), 10.0, seed=1)
    vad.reset()
    found = SpeechDetector(vad).feed(audio.samples)
    assert len(found) == 2
    assert all(0.8 < u.audio.seconds < question.seconds + 0.5 for u in found)


def test_the_end_of_speech_is_found_within_about_300_ms_of_silence(
    voices: dict, vad: SileroVad
) -> None:
    speech = voices["joe"].synthesize("what is the temperature").resampled(SPEECH_RATE_HZ)
    quiet = Audio.silence(2.0)
    detector = SpeechDetector(vad)
    vad.reset()
    found = detector.feed(stream(Audio.silence(0.5), speech, quiet).samples)
    assert len(found) == 1
    speech_ends = round((0.5 + speech.seconds) * SPEECH_RATE_HZ)
    waited_s = (found[0].end_sample - speech_ends) / SPEECH_RATE_HZ
    assert waited_s <= 0.3 + 3 * FRAME_S  # the silence to wait for, and the voice's own tail


def test_a_room_s_noise_alone_never_starts_an_utterance(vad: SileroVad) -> None:
    vad.reset()
    for level in (-50.0, -30.0, -20.0):
        assert SpeechDetector(vad).feed(noise(10.0, level, seed=7).samples) == []


class CountingVad:
    """A SileroVad that counts the frames it is asked about."""

    def __init__(self, vad: SileroVad) -> None:
        self.vad, self.asked, self.resets = vad, 0, 0

    def __call__(self, frame: object) -> float:
        self.asked += 1
        return self.vad(frame)  # type: ignore[arg-type]

    def reset(self) -> None:
        self.resets += 1
        self.vad.reset()


def test_a_steadily_humming_room_is_not_asked_about_and_a_question_in_it_is_still_heard(
    spoken: Callable[..., Audio], vad: SileroVad
) -> None:
    vad.reset()
    counting = CountingVad(vad)
    detector = SpeechDetector(counting)
    hum = noise(10.0, -45.0, seed=3)
    assert detector.feed(hum.samples) == []
    frames = round(hum.seconds / FRAME_S)
    assert counting.asked < frames // 20  # the floor learns the hum within a frame or two

    question = spoken("what is your name")
    asked_before = counting.asked
    said = with_noise(stream(question, Audio.silence(1.0)), 10.0, seed=4)  # 10 dB over speech
    found = detector.feed(said.samples)
    assert len(found) == 1
    assert counting.asked > asked_before  # the question rose above the floor
    assert counting.resets == 1  # and the network started afresh after 10 s of hum


def test_without_a_noise_floor_every_frame_is_asked_about(vad: SileroVad) -> None:
    vad.reset()
    counting = CountingVad(vad)
    hum = noise(3.0, -45.0, seed=3)
    SpeechDetector(counting, noise_floor=None).feed(hum.samples)
    assert counting.asked == len(hum.samples) // FRAME_SAMPLES
