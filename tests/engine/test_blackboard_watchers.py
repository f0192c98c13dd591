"""A blackboard watcher (the timeline, a debug view) that fails never loses a write."""

import logging

import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import VirtualClock


def test_a_failing_watcher_is_logged_once_counted_and_the_commit_goes_on(
    caplog: pytest.LogCaptureFixture,
) -> None:
    board = Blackboard(default_catalogue(), VirtualClock())
    board.reset()
    seen: list[str] = []

    def full_disk(key: str, value: object) -> None:
        raise OSError(28, "No space left on device")

    board.watchers.extend([full_disk, lambda key, value: seen.append(key)])
    board.stage_event("/sensors/gesture/last", "wave")
    board.stage("/sensors/touch/any", True)
    with caplog.at_level(logging.ERROR):
        assert board.commit() == 2
        board.stage("/sensors/touch/any", False)
        board.commit()

    # every write landed, and the watcher after the failing one heard of each
    assert board.event_log("/sensors/gesture/last").last_seq == 1
    assert board.get("/sensors/touch/any") is False
    assert seen == ["/sensors/gesture/last", "/sensors/touch/any", "/sensors/touch/any"]
    assert board.watcher_failures(full_disk) == 3
    failures = [r for r in caplog.records if "watcher" in r.getMessage()]
    assert len(failures) == 1
    assert "No space left on device" in failures[0].getMessage()
