"""A child who pauses and goes on keeps the speaker until the second part is heard too.

A child's sentence often has a pause long enough to end an utterance ("my favourite animal
is ... a big brown dog"). The person's turn lasts until the latest part is heard, so an
answer to the first part does not start over the second. The listener missed a part that
began in the piece of audio in which the first ended (its turn was never taken); it now
tells each part that begins.
"""

from __future__ import annotations

import json
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import TOUCH_PAT, default_catalogue
from engine.cli import main
from engine.clock import VirtualClock
from engine.media.audio import SPEECH_RATE_HZ, Audio
from engine.runtime.robot import Robot, load_behaviors
from engine.services.simulated import simulated_services
from engine.speech.listener import Listener
from engine.speech.recognizers import NoWords
from engine.speech.vad import SileroVad, speech_detector
from engine.speech.voice_models import default_voice
from engine.speech.voices import steady_voice

THANKS = """\
rate_hz: 10
wake_on: [/sensors/touch/pat]
root:
  Sequence:
    - OnEvent: {key: /sensors/touch/pat}
    - Say: {text: thank you}
"""


class Floor:
    """A person's turn, over when the test says what they said was heard."""

    def __init__(self) -> None:
        self.heard = False

    def done(self) -> bool:
        return self.heard

    def error(self) -> BaseException | None:
        return None

    def result(self) -> Any:
        return None

    def cancel(self) -> None:
        self.heard = True


def test_an_answer_to_the_first_part_does_not_start_over_the_second(tmp_path: Path) -> None:
    (tmp_path / "thanks.yaml").write_text(textwrap.dedent(THANKS))
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    services = simulated_services(clock)
    robot = Robot(load_behaviors([tmp_path]), clock=clock, services=services, blackboard=board)
    first, second = Floor(), Floor()
    robot.person_speaks(0.5, first)  # "my favourite animal is"
    robot.person_speaks(1.6, second)  # "... a big brown dog", before the first was heard
    first.heard = True
    board.stage_event(TOUCH_PAT, "middle_back")  # a pat while the child is still talking
    robot.scheduler.run(until_s=2.0)
    assert robot.action_log.records == []  # the thanks waits for no one: it is let go

    second.heard = True
    board.stage_event(TOUCH_PAT, "middle_back")
    robot.scheduler.run(until_s=3.0)
    assert [r.args["text"] for r in robot.action_log.records] == ["thank you"]


@pytest.mark.models
def test_the_listener_tells_a_part_that_begins_as_the_first_ends() -> None:
    voice = steady_voice(default_voice(None)[0])
    part = voice.synthesize("my favourite animal is").resampled(SPEECH_RATE_HZ).samples
    rate = SPEECH_RATE_HZ
    pause = np.zeros(int(0.4 * rate), np.float32)  # ends the first part (0.3 s of silence)
    audio = np.concatenate([np.zeros(rate // 2, np.float32), part, pause, part, np.zeros(rate)])
    began: list[float] = []
    clock = VirtualClock()
    listener = Listener(speech_detector(SileroVad()), NoWords(), clock, lambda heard: None)
    listener.on_voice = began.append
    piece = rate // 2  # half-second pieces: the second part begins in the piece the first ends
    for end in range(piece, len(audio) + 1, piece):
        clock.advance(0.5)
        listener.hear(Audio(audio[end - piece : end], rate), clock.now())
    listener.close()
    assert len(began) == 2


@pytest.mark.models
def test_a_child_who_goes_on_over_the_robot_s_question_is_answered_whole(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # "do you like" ... the robot asks whether it heard a question about animals, and the
    # child goes on over it: "puppies". The robot stops and answers the whole sentence.
    monkeypatch.chdir(Path(__file__).resolve().parents[2])
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text(
        """\
duration_s: 14
events:
  - {at: 0.5, hear: "hello robot"}   # the robot speaks once: it learns the room
  - {at: 5.0, hear: "do you like"}
  - {at: 7.0, hear: "puppies"}
""",
        encoding="utf-8",
    )
    args = ["run", "--fast", "--json", "--trees", "trees/dialog.yaml", "--scenario", str(scenario)]
    assert main([*args, "--profile", "child"]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines() if line]
    said = [e["args"]["text"] for e in lines if e["event"] == "action" and e["action"] == "say"]
    assert said == [
        "Hello! Nice to see you.",
        "Did you ask whether I like animals?",  # spoken over
        "I love animals. Do you have a pet?",
    ]
    assert [e["saying"] for e in lines if e["event"] == "spoken_over"] == [
        "Did you ask whether I like animals?"
    ]
