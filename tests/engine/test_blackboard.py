"""The blackboard: staged writes appear only at commit; events are handled once each."""

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import VirtualClock


def make_board() -> tuple[Blackboard, VirtualClock]:
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    return board, clock


def test_a_staged_write_is_invisible_until_the_scheduler_commits_it():
    board, _ = make_board()
    board.stage("/sensors/force/left_n", 6.0)
    assert board.get("/sensors/force/left_n") is None
    assert board.commit() == 1
    assert board.get("/sensors/force/left_n") == 6.0


def test_commit_applies_writes_in_order_so_the_last_one_wins():
    board, _ = make_board()
    board.stage("/sensors/touch/any", True)
    board.stage("/sensors/touch/any", False)
    board.commit()
    assert board.get("/sensors/touch/any") is False


def test_every_event_gets_its_own_sequence_number_even_with_the_same_value():
    board, clock = make_board()
    board.stage_event("/sensors/gesture/last", "wave")
    board.stage_event("/sensors/gesture/last", "wave")
    clock.advance(0.5)
    board.commit()
    log = board.event_log("/sensors/gesture/last")
    assert [(e.seq, e.value, e.at_s) for e in log.events] == [(1, "wave", 0.5), (2, "wave", 0.5)]
    assert [e.seq for e in log.after(1)] == [2]
    assert log.after(2) == ()


def test_the_board_remembers_when_each_key_last_changed():
    board, clock = make_board()
    clock.advance(2.0)
    board.set("/sensors/range/left_mm", 300.0)
    assert board.updated_s("/sensors/range/left_mm") == 2.0
    assert board.updated_s("/sensors/range/right_mm") is None


def test_the_catalogue_knows_device_keys_and_tree_variables_and_suggests_near_misses():
    catalogue = default_catalogue()
    assert catalogue.lookup("/devices/touch/ok").value_type is bool
    assert catalogue.lookup("/vars/anything") is not None
    assert catalogue.lookup("/devices/touch/extra/ok") is None
    assert catalogue.suggest("/sensors/forse/left_n") == "/sensors/force/left_n"
    assert catalogue.lookup("/speech/heard").kind == "event"
