"""An action the service failed is recorded as failed, not as done.

The ActionLog hears of every call when it is made (the timeline prints it at once); when
the call's job is first seen failed, the record gets its ``error`` and the log's
``failure_listeners`` hear ``(record, error)``. The harness's ``said`` and ``did()``
leave failed calls out; ``failed_actions`` lists them.
"""

from __future__ import annotations

from concurrent.futures import Future
from pathlib import Path
from typing import Any

from py_trees.common import Status

from engine.clock import VirtualClock
from engine.errors import ServiceError
from engine.services.actions import ActionLog, ActionRecord, TreeActions
from engine.services.jobs import FutureJob
from engine.services.simulated import simulated_services
from engine.testing import TreeHarness

WAVE_GREETING = Path(__file__).resolve().parents[2] / "trees" / "wave_greeting.yaml"


class Failures:
    """A failure listener that remembers what it heard."""

    def __init__(self) -> None:
        self.heard: list[tuple[ActionRecord, BaseException]] = []

    def __call__(self, record: ActionRecord, error: BaseException) -> None:
        self.heard.append((record, error))


def actions_with(log: ActionLog, **services: Any) -> TreeActions:
    clock = VirtualClock()
    simulated = simulated_services(clock)
    for name, service in services.items():
        setattr(simulated, name, service)
    return TreeActions(simulated, clock, "hug", log)


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


def test_a_refused_call_is_marked_failed_and_told_to_the_failure_listeners_at_once() -> None:
    failures = Failures()
    log = ActionLog(failure_listeners=[failures])
    actions = actions_with(log)
    actions.services.speech.fail_next = "speaker unplugged"

    job = actions.say("hello")

    [record] = log.records
    assert record.error == "speaker unplugged"
    assert record.failed
    assert [(r, str(e)) for r, e in failures.heard] == [(record, "speaker unplugged")]
    assert isinstance(job.error(), ServiceError)
    assert len(failures.heard) == 1  # asking again tells nobody twice


def test_a_job_failing_later_is_marked_when_its_node_sees_it_fail() -> None:
    failures = Failures()
    log = ActionLog(failure_listeners=[failures])
    future: Future[Any] = Future()

    class SlowSpeech:
        def say(self, text: str, *, volume: float | None = None) -> FutureJob:
            return FutureJob(future)

    job = actions_with(log, speech=SlowSpeech()).say("hello")
    assert not job.done()
    assert log.records[0].error is None  # under way: not failed (yet)

    future.set_exception(ServiceError("TTS crashed"))
    assert job.done()
    assert log.records[0].error == "TTS crashed"
    assert len(failures.heard) == 1


def test_a_cancelled_call_is_not_a_failure() -> None:
    failures = Failures()
    log = ActionLog(failure_listeners=[failures])
    actions = actions_with(log)
    actions.services.speech.seconds_per_word = 0.3
    job = actions.say("a long story")

    job.cancel()  # its node was pre-empted

    assert job.done()
    assert log.records[0].error is None
    assert failures.heard == []


def test_the_json_of_a_record_is_unchanged_and_a_failed_one_adds_its_error() -> None:
    record = ActionRecord(1.23456, "hug", "say", {"text": "hi"})
    assert record.to_json() == {"t": 1.235, "tree": "hug", "action": "say", "args": {"text": "hi"}}
    ActionLog().failed(record, ServiceError("speaker unplugged"))
    assert record.to_json()["error"] == "speaker unplugged"


def test_a_broken_failure_listener_does_not_stop_the_robot() -> None:
    def broken(record: ActionRecord, error: BaseException) -> None:
        raise RuntimeError("display gone")

    failures = Failures()
    log = ActionLog(failure_listeners=[broken, failures])
    actions = actions_with(log)
    actions.services.leds.fail_next = "LED driver missing"
    actions.set_led("pink")
    assert len(failures.heard) == 1
