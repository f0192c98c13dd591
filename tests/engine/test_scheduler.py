"""The scheduler: each tree at its own rate, drift-free, and a failing leaf never stops it."""

import dataclasses
import logging
import textwrap
from pathlib import Path

import pytest
from py_trees.common import Status

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import default_catalogue
from engine.clock import VirtualClock
from engine.errors import ConfigError
from engine.nodes import Condition, Param, Text, builtin_registry
from engine.nodes.context import NodeErrorLog
from engine.runtime.robot import Robot, load_behaviors
from engine.services.simulated import simulated_services


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path


def make_robot(trees: Path, registry=None) -> tuple[Robot, VirtualClock]:
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    behaviors = load_behaviors([trees], registry=registry)
    robot = Robot(behaviors, clock=clock, services=simulated_services(clock), blackboard=board)
    return robot, clock


def test_each_tree_ticks_at_its_own_rate(tmp_path):
    write(tmp_path, "fast.yaml", "rate_hz: 20\nroot:\n  Wait: {seconds: 100}\n")
    write(tmp_path, "slow.yaml", "rate_hz: 4\nroot:\n  Wait: {seconds: 100}\n")
    robot, clock = make_robot(tmp_path)
    robot.scheduler.run(until_s=1.0)
    ticks = {tree.name: tree.stats.ticks for tree in robot.trees}
    # deadlines at 0, 0.05, ..., 1.0 and 0, 0.25, ..., 1.0
    assert ticks == {"fast": 21, "slow": 5}
    assert clock.now() == 1.0


def test_deadlines_do_not_drift_when_ticks_start_late(tmp_path):
    write(tmp_path, "t.yaml", "rate_hz: 10\nroot:\n  Wait: {seconds: 100}\n")
    robot, clock = make_robot(tmp_path)
    tree = robot.trees[0]
    robot.scheduler.step()  # tick at 0.0
    clock.advance(0.13)  # woke 30 ms late for the 0.1 deadline
    robot.scheduler.step()
    assert tree.next_deadline_s == 0.2  # not 0.23
    assert abs(tree.stats.lateness_s[-1] - 0.03) < 1e-9


def test_whole_periods_missed_by_an_overrun_are_skipped_and_counted(tmp_path):
    write(tmp_path, "t.yaml", "rate_hz: 10\nroot:\n  Wait: {seconds: 100}\n")
    robot, clock = make_robot(tmp_path)
    tree = robot.trees[0]
    robot.scheduler.step()
    clock.advance(0.45)  # deadlines 0.1, 0.2, 0.3, 0.4 have all passed
    robot.scheduler.step()
    assert tree.stats.skipped == 3
    assert abs(tree.next_deadline_s - 0.5) < 1e-9


class Explodes(Condition):
    """Raises every time (a developer's bug). SUCCESS never."""

    params = (Param("why", Text(), "bug"),)

    def check(self) -> bool:
        raise RuntimeError(self.args.why)


def test_an_exception_in_a_leaf_makes_it_fail_is_reported_with_its_path_and_ticking_goes_on(
    tmp_path,
):
    registry = builtin_registry()
    registry.add(Explodes)
    write(
        tmp_path,
        "t.yaml",
        """\
        name: fragile
        rate_hz: 10
        root:
          Selector:
            - Explodes: {why: "divide by zero", name: boom}
            - Say: {text: "still here"}
        """,
    )
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    errors = []
    robot = Robot(
        load_behaviors([tmp_path], registry=registry),
        clock=clock,
        services=simulated_services(clock),
        blackboard=board,
        on_node_error=lambda tree, path, error: errors.append((tree, path, str(error))),
    )
    robot.scheduler.run(until_s=0.2)
    assert errors[0] == ("fragile", "Selector/boom", "divide by zero")
    assert len(errors) == 3  # ticks at 0.0, 0.1, 0.2
    assert [r.args["text"] for r in robot.action_log.records] == ["still here"] * 3
    assert robot.trees[0].status == Status.SUCCESS


def test_stop_ends_the_run_after_the_current_tick(tmp_path):
    write(tmp_path, "t.yaml", "rate_hz: 10\nroot:\n  Wait: {seconds: 100}\n")
    robot, _ = make_robot(tmp_path)
    robot.scheduler.add_hook(lambda now: robot.scheduler.stop() if now >= 0.3 else None)
    robot.scheduler.run()
    assert robot.trees[0].stats.ticks == 4  # 0.0, 0.1, 0.2, 0.3


def test_stopping_the_run_cancels_what_a_tree_was_still_doing(tmp_path):
    write(
        tmp_path,
        "t.yaml",
        'name: talker\nrate_hz: 10\nroot:\n  Say: {text: "a very long story indeed"}\n',
    )
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    services = simulated_services(clock, realistic=True)  # speaking takes time
    robot = Robot(load_behaviors([tmp_path]), clock=clock, services=services, blackboard=board)
    jobs = []
    original = services.speech.say
    services.speech.say = lambda text, **kw: jobs.append(original(text, **kw)) or jobs[-1]
    robot.scheduler.run(until_s=0.3)
    assert robot.trees[0].status != Status.RUNNING
    assert jobs[0].cancelled


def test_time_spent_in_hooks_counts_as_lateness(tmp_path):
    write(tmp_path, "t.yaml", "rate_hz: 10\nroot:\n  Wait: {seconds: 100}\n")
    robot, clock = make_robot(tmp_path)
    robot.scheduler.add_hook(lambda now: clock.advance(0.03))
    robot.scheduler.run(until_s=0.25)
    assert max(robot.trees[0].stats.lateness_s) >= 0.03 - 1e-9


def test_a_failing_hook_is_counted_and_the_trees_keep_ticking(tmp_path):
    write(tmp_path, "t.yaml", "rate_hz: 10\nroot:\n  Wait: {seconds: 100}\n")
    robot, _ = make_robot(tmp_path)

    def broken(now):
        raise ValueError("scenario bug")

    robot.scheduler.add_hook(broken)
    robot.scheduler.run(until_s=0.2)
    assert robot.scheduler.hook_errors == 3
    assert robot.trees[0].stats.ticks == 3


def test_a_tree_built_in_code_with_an_absurd_rate_is_refused_before_it_can_spin(tmp_path):
    write(tmp_path, "calm.yaml", "rate_hz: 10\nroot:\n  Wait: {seconds: 1}\n")
    robot, _ = make_robot(tmp_path)
    [running] = robot.trees
    running.definition = dataclasses.replace(running.definition, rate_hz=5e-324)
    with pytest.raises(ConfigError, match=r"rate_hz must be 0.1..1000, got 5e-324"):
        robot.scheduler.add(running)


def test_a_node_failing_at_every_tick_is_logged_once_then_counted(tmp_path, caplog):
    class Broken(Condition):
        def check(self) -> bool:
            raise RuntimeError("no reads declared")

    registry = builtin_registry()
    registry.add(Broken)
    write(tmp_path, "broken.yaml", "rate_hz: 10\nroot:\n  Broken: {}\n")
    errors = NodeErrorLog(logging.getLogger("vest.test.nodes"))
    clock = VirtualClock()
    board = Blackboard(default_catalogue(), clock)
    board.reset()
    behaviors = load_behaviors([tmp_path], registry=registry)
    robot = Robot(
        behaviors,
        clock=clock,
        services=simulated_services(clock),
        blackboard=board,
        on_node_error=errors,
    )
    with caplog.at_level(logging.ERROR, logger="vest.test.nodes"):
        robot.scheduler.run(until_s=59.95)  # 600 ticks, 600 failures
    lines = [record.getMessage() for record in caplog.records]
    assert lines == [
        "broken: node Broken failed: RuntimeError: no reads declared",
        "broken: node Broken failed with RuntimeError 10 times so far",
        "broken: node Broken failed with RuntimeError 100 times so far",
    ]
    assert errors.counts == {("broken", "Broken", "RuntimeError"): 600}
