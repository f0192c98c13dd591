"""An action the service failed is recorded as failed, not as done; one cut short, as cut.

The ActionLog publishes every call on the session stream when it is made (the timeline
prints it at once, as an ``action`` event) and, when its job is first seen to end, how it
ended (an ``outcome``: failed with why, cut short with why, or done). The harness's
``said`` and ``did()`` leave failed calls out; ``failed_actions`` lists them.
"""

from __future__ import annotations

from concurrent.futures import Future
from pathlib import Path
from typing import Any

from py_trees.common import Status

from engine.clock import VirtualClock
from engine.errors import ServiceError
from engine.services.actions import ActionLog, TreeActions
from engine.services.jobs import FutureJob
from engine.services.simulated import simulated_services
from engine.session.events import ActionEnded, ActionStarted, SessionEvent
from engine.session.stream import EventCollector, SessionStream
from engine.testing import TreeHarness

WAVE_GREETING = Path(__file__).resolve().parents[2] / "trees" / "wave_greeting.yaml"


def a_log() -> tuple[ActionLog, EventCollector]:
    """An action log on a stream that a collector reads."""
    stream = SessionStream(VirtualClock())
    heard = EventCollector()
    stream.subscribe(heard)
    return ActionLog(stream), heard


def actions_with(log: ActionLog, **services: Any) -> TreeActions:
    clock = VirtualClock()
    simulated = simulated_services(clock)
    for name, service in services.items():
        setattr(simulated, name, service)
    return TreeActions(simulated, clock, "hug", log)


def outcomes(heard: EventCollector) -> list[tuple[str, str]]:
    return [(e.outcome, e.why) for e in heard.of(ActionEnded)]


def test_a_phrase_the_speaker_failed_is_not_counted_as_said() -> None:
    robot = TreeHarness.from_file(WAVE_GREETING)
    robot.services.speech.fail_next = "speaker unplugged"
    robot.set("/sensors/gesture/last", "wave")
    assert robot.tick() == Status.RUNNING  # the greeting's light still comes on for its second
    assert robot.advance(1.0) == Status.FAILURE  # then the greeting reports the failed say

    assert robot.said == []
    [failed] = robot.failed_actions
    assert (failed.action, failed.error) == ("say", "speaker unplugged")
    assert failed in robot.actions  # still a call the tree made
    assert robot.did("led") == [{"color": "green", "seconds": 1.0}]  # the light did come on


def test_a_refused_call_is_marked_failed_and_its_outcome_published_at_once() -> None:
    log, heard = a_log()
    actions = actions_with(log)
    actions.services.speech.fail_next = "speaker unplugged"

    job = actions.say("hello")

    [record] = log.records
    assert record.error == "speaker unplugged"
    assert record.failed
    [started] = heard.of(ActionStarted)
    assert (started.tree, started.action, started.args) == ("hug", "say", {"text": "hello"})
    assert outcomes(heard) == [("failed", "speaker unplugged")]
    assert isinstance(job.error(), ServiceError)
    assert len(heard.of(ActionEnded)) == 1  # asking again tells nobody twice


def test_a_job_failing_later_is_marked_when_its_node_sees_it_fail() -> None:
    log, heard = a_log()
    future: Future[Any] = Future()

    class SlowSpeech:
        def say(
            self, text: str, *, volume: float | None = None, interruptible: bool = True
        ) -> FutureJob:
            return FutureJob(future)

    job = actions_with(log, speech=SlowSpeech()).say("hello")
    assert not job.done()
    assert log.records[0].error is None  # under way: not failed (yet)
    assert outcomes(heard) == []

    future.set_exception(ServiceError("TTS crashed"))
    assert job.done()
    assert log.records[0].error == "TTS crashed"
    assert outcomes(heard) == [("failed", "TTS crashed")]


def test_a_cancelled_call_is_cut_short_not_failed() -> None:
    log, heard = a_log()
    actions = actions_with(log)
    actions.services.speech.seconds_per_word = 0.3
    job = actions.say("a long story")

    actions.stop_reason = "touch_thanks interrupted it"
    job.cancel()  # its node was pre-empted

    assert job.done()
    assert log.records[0].error is None
    assert log.records[0].cut
    assert outcomes(heard) == [("cut", "touch_thanks interrupted it")]


def test_a_call_done_as_asked_is_published_done_once() -> None:
    log, heard = a_log()
    job = actions_with(log).set_led("pink")
    assert job.done() and job.done()
    assert outcomes(heard) == [("done", "")]


def test_a_broken_reader_does_not_stop_the_robot() -> None:
    def broken(event: SessionEvent) -> None:
        raise RuntimeError("display gone")

    stream = SessionStream(VirtualClock())
    failing = EventCollector(broken)
    heard = EventCollector()
    stream.subscribe(failing)
    stream.subscribe(heard)
    actions = actions_with(ActionLog(stream))
    actions.services.leds.fail_next = "LED driver missing"
    actions.set_led("pink")
    assert len(heard.of(ActionEnded)) == 1
    assert stream.failures(failing) == 2  # the call and its outcome: counted, not raised
