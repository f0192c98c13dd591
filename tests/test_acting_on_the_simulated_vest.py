"""A therapist trying a session on the simulated vest squeezes, touches or speaks for the
child from the buttons page: the robot feels it at once, as a scenario's event at that
moment; anything else the page sends is refused with its place."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.buttons.acting import ActingNow
from engine.clock import VirtualClock
from engine.files.problems import LoadError
from engine.hardware.config_file import load_robot_config
from engine.scenario.player import ScenarioPlayer
from engine.scenario.scenario_file import Scenario, ScenarioEvent
from engine.scenario.world import World

ROOT = Path(__file__).resolve().parents[1]


class Session:
    """Ten seconds into a session on the simulated vest, nothing scripted."""

    def __init__(self) -> None:
        self.clock = VirtualClock()
        self.world = World()
        self.told: list[tuple[float, str]] = []
        self.player = ScenarioPlayer(
            Scenario(60.0, (), ROOT / "quiet.yaml"),
            self.world,
            start_s=2.0,
            on_event=lambda at_s, event: self.told.append((at_s, event.describe())),
        )
        config = load_robot_config(ROOT / "examples" / "robots" / "sim.yaml")
        self.acting = ActingNow(self.player, self.clock, config)
        self.clock.advance(10.0)

    def at(self, seconds: float) -> None:
        self.clock.advance(seconds - self.clock.now())
        self.player(self.clock.now())

    def refused(self, text: str) -> str:
        with pytest.raises(LoadError) as refusal:
            self.acting.act(text)
        return str(refusal.value)


def test_a_squeeze_from_the_page_is_felt_now_and_lets_go_when_it_ends() -> None:
    session = Session()
    event = session.acting.act('{"squeeze": {"left_n": 6, "right_n": 6, "seconds": 1.5}}')
    assert isinstance(event, ScenarioEvent) and event.at_s == 8.0  # from the session's start
    session.at(10.0)
    assert session.world.force_n == {"left": 6.0, "right": 6.0}
    assert session.told == [(10.0, "squeezed left 6 N, right 6 N for 1.5 s")]
    session.at(11.5)
    assert session.world.force_n == {"left": 0.0, "right": 0.0}


def test_a_touch_names_the_robot_s_own_pad_and_the_child_s_words_are_said_in_the_room() -> None:
    session = Session()
    heard: list[tuple[str, object]] = []

    class Ears:
        def world_changed(self, world: World, what: str) -> None:
            pass

        def world_event(self, kind: str, value: object) -> None:
            heard.append((kind, value))

    session.world.add_listener(Ears())
    session.acting.act('{"touch": {"pad": "left_arm", "seconds": 0.5}}')
    session.acting.act('{"hear": "what is your name"}')
    session.at(10.0)
    [pad] = [i for i, down in enumerate(session.world.touched) if down]
    assert session.told[0] == (10.0, "left_arm touched for 0.5 s")
    assert heard == [("hear", {"text": "what is your name", "wav": None, "snr_db": None})]
    session.at(10.5)
    assert not session.world.touched[pad]


@pytest.mark.parametrize(
    ("sent", "problem"),
    [
        ('{"cloud": {"type": "say"}}', "the request:1:2: the page cannot act 'cloud'"),
        ('{"squeze": {"left_n": 6}}', "did you mean 'squeeze'?"),
        ('{"squeeze": {"left_n": 600}}', "the request:1:24: 'left_n' must be at most 100"),
        ('{"squeeze": {"seconds": 2}}', "the request:1:13: a squeeze needs a force on one side"),
        ('{"hear": "hello\\u0000there"}', "the request:1:10: write the child's words, in plain"),
        ('{"hear": "  "}', "the request:1:10: hear has no words to say"),
        ('{"touch": {"pad": "left_hand"}}', "(did you mean 'left_arm'?)"),
        ('{"hear": {"wav": "/etc/passwd"}}', "the request:1:11: from the page, write the words"),
        ('{"squeeze": {}, "touch": {}}', "send one thing to do"),
        ("[1, 2]", "send one thing to do"),
        ("", "send one thing to do"),
        ('{"squeeze": ', "YAML syntax error"),
    ],
)
def test_what_the_page_cannot_do_is_refused_with_its_place_and_nothing_is_played(
    sent: str, problem: str
) -> None:
    session = Session()
    assert problem in session.refused(sent)
    session.at(20.0)
    assert session.told == [] and session.world.force_n == {"left": 0.0, "right": 0.0}
