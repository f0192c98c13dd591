"""Trees that wake when something happens (``wake_on:``): a tree rests between rounds and
ticks at once when one of its keys changes, never faster than its rate."""

import textwrap
from pathlib import Path

import pytest

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import FORCE_SQUEEZE, TOUCH_PAT, default_catalogue
from engine.clock import VirtualClock
from engine.files.problems import LoadError
from engine.runtime.robot import Robot, load_behaviors
from engine.services.simulated import simulated_services

THANKS = """\
rate_hz: 10
wake_on: [/sensors/touch/pat]
root:
  Sequence:
    - OnEvent: {key: /sensors/touch/pat}
    - Say: {text: thank you}
"""


def robot_with(folder: Path, **trees: str) -> tuple[Robot, Blackboard, VirtualClock]:
    for name, text in trees.items():
        (folder / f"{name}.yaml").write_text(textwrap.dedent(text))
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    behaviors = load_behaviors([folder])
    robot = Robot(behaviors, clock=clock, services=simulated_services(clock), blackboard=board)
    return robot, board, clock


def test_a_tree_that_waits_on_a_pat_rests_until_one_comes(tmp_path: Path) -> None:
    robot, _, _ = robot_with(tmp_path, thanks=THANKS)
    robot.scheduler.run(until_s=2.0)
    assert robot.trees[0].stats.ticks == 1  # its first round, then rest: no 20 idle ticks


def test_a_pat_is_answered_at_once_not_at_the_next_deadline(tmp_path: Path) -> None:
    robot, board, clock = robot_with(tmp_path, thanks=THANKS)
    thanks = robot.trees[0]
    robot.scheduler.step()  # t = 0: the first round, then it rests
    clock.advance(0.33)  # between its deadlines (0.3, 0.4)
    board.stage_event(TOUCH_PAT, "middle_back")
    robot.scheduler.step()
    assert thanks.stats.ticks == 2 and thanks.last_tick_s == pytest.approx(0.33)
    assert robot.services.speech.calls[-1][0] == "thank you"  # type: ignore[attr-defined]


def test_its_rate_stays_the_fastest_it_ticks(tmp_path: Path) -> None:
    robot, board, clock = robot_with(tmp_path, thanks=THANKS)
    thanks = robot.trees[0]
    robot.scheduler.step()
    clock.advance(0.33)
    board.stage_event(TOUCH_PAT, "middle_back")
    robot.scheduler.step()  # woken at 0.33
    for _ in range(3):  # the round ran at once (Say is instant here): it rests again
        robot.scheduler.step()
    clock.advance(0.03)
    board.stage_event(TOUCH_PAT, "middle_back")  # 30 ms later: too soon for 10 Hz
    robot.scheduler.step()
    assert thanks.stats.ticks == 2
    clock.advance(0.07)  # a period after its last tick
    robot.scheduler.step()
    assert thanks.stats.ticks == 3 and thanks.last_tick_s == pytest.approx(0.43)


def test_while_a_round_runs_the_tree_ticks_at_its_rate_then_rests(tmp_path: Path) -> None:
    waits = """\
    rate_hz: 10
    wake_on: [/sensors/force/squeeze]
    root:
      Sequence:
        - OnEvent: {key: /sensors/force/squeeze}
        - Wait: {seconds: 0.5}
    """
    robot, board, clock = robot_with(tmp_path, hug=waits)
    robot.scheduler.step()
    board.stage_event(FORCE_SQUEEZE, 30.0)
    robot.scheduler.run(until_s=3.0)
    # t=0, the squeeze at 0.1 and the Wait's round 0.1..0.6 at 10 Hz, one tick that finds
    # nothing to do (its nodes say they wait again), then rest
    assert robot.trees[0].stats.ticks == 8
    assert clock.now() == 3.0


def test_a_reading_staged_again_unchanged_wakes_nobody(tmp_path: Path) -> None:
    _, board, _ = robot_with(
        tmp_path,
        near="""\
        rate_hz: 10
        wake_on: [/sensors/range/center_mm]
        root:
          Check: {key: /sensors/range/center_mm, below: 300}
        """,
    )
    woken: list[bool] = []
    board.on_wake = lambda: woken.append(True)
    board.stage("/sensors/range/center_mm", 500.0)
    board.stage("/sensors/range/center_mm", 500.0)  # the poller's next read, the same
    board.stage("/sensors/range/center_mm", 250.0)
    assert len(woken) == 2


def test_a_tree_cannot_wait_on_a_key_nobody_writes(tmp_path: Path) -> None:
    (tmp_path / "t.yaml").write_text(
        "wake_on: [/sensors/touch/pats]\nroot:\n  Wait: {seconds: 1}\n"
    )
    with pytest.raises(LoadError) as raised:
        load_behaviors([tmp_path])
    message = str(raised.value)
    assert "t.yaml:1:" in message and "/sensors/touch/pat" in message  # where, and the fix


def test_a_tree_cannot_wait_on_a_variable_no_tree_writes(tmp_path: Path) -> None:
    (tmp_path / "t.yaml").write_text("wake_on: [/vars/ready]\nroot:\n  Wait: {seconds: 1}\n")
    with pytest.raises(LoadError, match="wakes on '/vars/ready', which no tree writes"):
        load_behaviors([tmp_path])
    (tmp_path / "writer.yaml").write_text("root:\n  SetValue: {key: /vars/ready, value: true}\n")
    assert len(load_behaviors([tmp_path]).trees) == 2


def test_two_commands_in_one_moment_are_both_carried_out(tmp_path: Path) -> None:
    commands = """\
    rate_hz: 10
    wake_on: [/iot/inbox]
    root:
      Sequence:
        - OnEvent: {key: /iot/inbox}
        - Say: {text: done}
    """
    robot, board, _ = robot_with(tmp_path, iot=commands)
    robot.scheduler.step()
    board.stage_event("/iot/inbox", {"id": "a"})
    board.stage_event("/iot/inbox", {"id": "b"})  # in the same commit: one a round
    robot.scheduler.run(until_s=2.0)
    said = [call[0] for call in robot.services.speech.calls]  # type: ignore[attr-defined]
    assert said == ["done", "done"]
    assert robot.trees[0].resting  # then it rests: nothing is left unread
