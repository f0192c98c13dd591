"""The branching clock: a poll's waits stay in its branch, the robot's time stays put."""

from __future__ import annotations

import threading

from engine.clock import VirtualClock
from engine.hardware.branching_clock import BranchingClock, branch_of


def test_sleeping_in_a_branch_moves_only_the_branch():
    base = VirtualClock(10.0)
    clock = BranchingClock(base)

    with clock.branch():
        clock.sleep(0.033)
        assert clock.now() == 10.033
        clock.sleep_until(10.050)
        assert clock.now() == 10.050

    assert clock.now() == base.now() == 10.0


def test_sleeping_outside_a_branch_moves_the_clock_it_wraps():
    base = VirtualClock()
    clock = BranchingClock(base)

    clock.sleep(0.5)

    assert base.now() == 0.5


def test_a_nested_branch_shares_the_outer_one():
    clock = BranchingClock(VirtualClock())

    with clock.branch():
        clock.sleep(0.1)
        with clock.branch():
            clock.sleep(0.1)
        assert clock.now() == 0.2
    assert clock.now() == 0.0


def test_other_threads_see_the_robot_s_time_during_a_branch():
    clock = BranchingClock(VirtualClock())
    seen: list[float] = []

    with clock.branch():
        clock.sleep(1.0)
        thread = threading.Thread(target=lambda: seen.append(clock.now()))
        thread.start()
        thread.join()

    assert seen == [0.0]


def test_any_other_clock_has_no_branches():
    base = VirtualClock()

    with branch_of(base):
        base.sleep(1.0)

    assert base.now() == 1.0
