"""The speaker: one utterance at a time, done when it has played, silent when stopped."""

from __future__ import annotations

import numpy as np

from engine.clock import VirtualClock
from engine.media.audio import Audio
from engine.speech.speaker import SelfHearing, Speaker


class WordVoice:
    """A fake voice: half a second of tone per word (the speaker's logic, not the model)."""

    name = "words"

    def __init__(self) -> None:
        self.sentences: list[str] = []

    def synthesize(self, sentence: str, *, speed: float = 1.0) -> Audio:
        self.sentences.append(sentence)
        count = round(0.5 * len(sentence.split()) * 1000 / speed)
        return Audio(np.full(count, 0.1, dtype=np.float32), 1000)


class Recorder:
    """A playback that remembers when each piece starts and when it was stopped."""

    def __init__(self) -> None:
        self.started: list[tuple[float, float]] = []
        self.stops = 0

    def start(self, audio: Audio, at_s: float) -> None:
        self.started.append((at_s, audio.seconds))

    def stop(self, at_s: float) -> None:
        self.stops += 1


def speaker_on(clock: VirtualClock) -> tuple[Speaker, Recorder, SelfHearing]:
    playback, hearing = Recorder(), SelfHearing(tail_s=0.4)
    speaker = Speaker(WordVoice(), playback, clock, self_hearing=hearing, instant_synthesis=True)
    return speaker, playback, hearing


def settle(speaker: Speaker) -> None:
    assert speaker.settling.wait(speaker.settled, timeout_s=10.0)


def test_an_answer_is_running_until_its_last_sentence_has_played() -> None:
    clock = VirtualClock()
    speaker, playback, _ = speaker_on(clock)
    job = speaker.say("Hello there. How are you today?")  # 2 words, then 4: 1 s + 2 s
    settle(speaker)
    assert playback.started == [(0.0, 1.0), (1.0, 2.0)]  # sentence by sentence, back to back
    clock.advance(2.9)
    assert not job.done()
    clock.advance(0.1)
    assert job.done() and job.error() is None
    speaker.close()


def test_two_trees_never_talk_over_each_other() -> None:
    clock = VirtualClock()
    speaker, playback, _ = speaker_on(clock)
    first = speaker.say("one two")  # 1 s
    second = speaker.say("three")  # asked at the same moment: waits
    settle(speaker)
    clock.advance(1.0)
    settle(speaker)
    assert [at for at, _ in playback.started] == [0.0, 1.0]
    assert first.done() and not second.done()
    clock.advance(0.5)
    assert second.done()
    speaker.close()


def test_a_halted_answer_stops_the_sound_and_the_microphone_listens_again() -> None:
    clock = VirtualClock()
    speaker, playback, hearing = speaker_on(clock)
    job = speaker.say("a long answer that goes on and on")  # 4 s
    settle(speaker)
    clock.advance(1.0)
    assert hearing.deaf_at(1.0)
    job.cancel()
    assert job.done()
    speaker.close()
    assert playback.stops == 1
    assert not hearing.deaf_at(1.5)  # quiet from 1.0, plus the 0.4 s tail


def test_the_microphone_is_deaf_while_the_robot_speaks_and_a_tail_after() -> None:
    clock = VirtualClock()
    speaker, _, hearing = speaker_on(clock)
    speaker.say("one two")  # 0..1 s
    settle(speaker)
    assert hearing.deaf_at(0.5) and hearing.deaf_at(1.3)
    assert not hearing.deaf_at(1.5)
    speaker.close()


class Unplugged:
    """A speaker whose card is gone."""

    def start(self, audio: Audio, at_s: float) -> None:
        raise RuntimeError("speaker 'hw:1,0' cannot be opened")

    def stop(self, at_s: float) -> None:
        """Nothing plays."""


def test_an_answer_the_speaker_cannot_play_fails_and_the_robot_still_listens() -> None:
    clock = VirtualClock()
    hearing = SelfHearing(tail_s=0.4)
    speaker = Speaker(WordVoice(), Unplugged(), clock, self_hearing=hearing, instant_synthesis=True)
    job = speaker.say("hello there")
    settle(speaker)
    assert job.done() and "hw:1,0" in str(job.error())
    assert not hearing.deaf_at(0.0) and not hearing.deaf_at(5.0)
    speaker.close()
