"""Every session event to JSON and back by the one codec: what a recording keeps, what
--json prints and what the interop topics carry are the same message."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from engine.session.codec import EventError, decode, encode
from engine.session.events import (
    EVENT_TYPES,
    ActionEnded,
    ActionStarted,
    BehaviorsPaused,
    ButtonPressed,
    DeviceChanged,
    HandShown,
    Heard,
    KeyChanged,
    NodeInfo,
    NodeStatus,
    NotListened,
    NotUnderstood,
    SafetyAction,
    SessionEnded,
    SessionEvent,
    SpokenOver,
    TreeReloaded,
    TreeStarted,
    TurnTaken,
    WorldEvent,
)

START_S = 100.0
ONE_OF_EACH: list[SessionEvent] = [
    TreeStarted(
        100.5,
        "hug",
        2,
        Path("trees/hug.yaml"),
        (Path("trees/hug.yaml"),),
        20.0,
        5,
        (NodeInfo(0, "/hug", "Sequence", "hug", 0, "in order"),),
        "digraph {}",
    ),
    NodeStatus(101.0, "hug", 2, 7, 0, "RUNNING", "waiting for a squeeze"),
    ActionStarted(101.0, 3, "hug", "say", {"text": "Thank you"}),
    ActionEnded(102.5, 3, "hug", "say", {"text": "Thank you"}, 101.0, "cut", "buttons"),
    TurnTaken(101.0, "hug", "yields", "speaker", "buttons", "saying 'Hi'"),
    SafetyAction(101.0, "refused", "left_arm", "still_within_mm", ("range_center",), "near"),
    ButtonPressed(101.0, "Well done", "page", done=False),
    BehaviorsPaused(101.0, True),
    DeviceChanged(101.0, "touch", False, first=True),
    Heard(101.0, "hello"),
    NotUnderstood(101.0, "dialog", "blue moon", "no rule", asked="yes", reprompt=1),
    NotListened(101.0, 100.2, 100.9, "the robot was speaking"),
    SpokenOver(101.2, "dialog", 4, "My name is H B S 2", 101.0),
    HandShown(101.0, 3),
    TreeReloaded(101.0, "hug", "line 3: no such node"),
    WorldEvent(101.0, "squeeze", "squeezed for 2 s", {"left_n": 6.0}),
    KeyChanged(101.0, "/sensors/force/left_n", 6.5, "6.5", False, "force_pads"),
    SessionEnded(112.0, {"why": "the scenario ended"}),
]


def test_every_kind_of_event_has_a_story_here() -> None:
    assert {type(event) for event in ONE_OF_EACH} == set(EVENT_TYPES)


@pytest.mark.parametrize("event", ONE_OF_EACH, ids=lambda event: event.kind)
def test_an_event_comes_back_from_its_json_as_it_was(event: SessionEvent) -> None:
    message = json.loads(json.dumps(encode(event, START_S)))  # through the text, as stored
    assert message["kind"] == event.kind
    assert decode(message, START_S) == event


def test_times_are_seconds_since_the_start_and_named_without_their_unit() -> None:
    cut = ONE_OF_EACH[3]
    message = encode(cut, START_S)
    assert (message["t"], message["started"]) == (2.5, 1.0)
    assert "t_s" not in message and "started_s" not in message
    assert encode(ONE_OF_EACH[11], START_S)["from"] == pytest.approx(0.2)


def test_a_reading_that_cannot_be_trusted_is_null_and_comes_back_as_nan() -> None:
    untrusted = KeyChanged(101.0, "/sensors/force/left_n", math.nan, "null", False, "force_pads")
    message = encode(untrusted, START_S)
    assert message["value"] is None and json.dumps(message, allow_nan=False)
    world = WorldEvent(101.0, "squeeze", "a fault", {"left_n": math.inf})
    assert encode(world)["value"] == {"left_n": None}


def test_what_only_the_consent_gate_reads_never_leaves_in_a_message() -> None:
    said = ActionStarted(101.0, 3, "dialog", "say", {"text": "Hello Lina"}, carries="speech")
    assert "carries" not in encode(said)


@pytest.mark.parametrize(
    ("message", "why"),
    [
        ({"kind": "gossip", "t": 1}, "no event of kind 'gossip'"),
        ({"t": 1}, "no event of kind None"),
        ({"kind": "hand", "t": 1}, "hand: no 'fingers'"),
        ({"kind": "hand", "t": 1, "fingers": True}, "hand.fingers: True is not int"),
        ({"kind": "hand", "t": "soon", "fingers": 2}, "hand.t: 'soon' is not float"),
        ({"kind": "hand", "t": None, "fingers": 2}, "hand.t: nan is not a time"),
        ({"kind": "hand", "t": -50, "fingers": 2}, "hand.t: -50.0 is not a time (seconds since"),
        ({"kind": "hand", "t": 1e300, "fingers": 2}, "hand.t: 1e+300 is not a time"),
        ({"kind": "press", "t": 1, "label": 3, "by": "page"}, "press.label: 3 is not str"),
        (
            {"kind": "press", "t": 1, "label": "x", "by": "alien"},
            "press.by: 'alien' is not one of 'page', 'key', 'scenario'",
        ),
        (
            {"kind": "press", "t": 1, "label": "x", "by": "page", "control": "explode"},
            "press.control: 'explode' is not one of '', 'pause'",
        ),
        (
            {"kind": "turn", "t": 1, "tree": "a", "turn": "shouts", "resource": "r", "other": "o"},
            "turn.turn: 'shouts' is not one of 'interrupts', 'waits'",
        ),
        ({"kind": "hand", "t": 10**400, "fingers": 2}, "hand.t: a number too large"),
        (
            {
                "kind": "tree",
                "t": 0,
                "tree": "a",
                "version": 1,
                "file": "a",
                "files": [],
                "rate_hz": 1.0,
                "priority": 0,
                "dot": "",
                "nodes": [{"index": 0, "path": "p", "type": "T", "depth": 0}],
            },
            "tree.nodes[]: no 'label'",
        ),
        (
            {
                "kind": "action",
                "t": 1,
                "action_id": 1,
                "tree": "a",
                "action": "say",
                "args": {"z": json.loads("[" * 100 + "]" * 100)},
            },
            "action.args: nested more than 64 deep",
        ),
        (
            {
                "kind": "safety",
                "t": 1,
                "action": "held",
                "joint": "j",
                "rule": "r",
                "devices": [1],
                "why": "w",
            },
            "safety.devices[]: 1 is not str",
        ),
    ],
)
def test_a_message_that_is_not_an_event_is_refused_by_its_field(
    message: dict[str, object], why: str
) -> None:
    with pytest.raises(EventError) as refused:
        decode(message)
    assert why in str(refused.value)
