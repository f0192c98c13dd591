"""An event one node of a tree took is the tree's: once the round is over, no other node
of the tree reacts to it.

The finger game started again after a child spoke over its praise: the count the game's
inner wait had taken was still new to the root's OnEvent. A round that ends (done, given
up, or halted and let go) now hands what it took to the whole tree; an event no node took
is still new to every node.
"""

from __future__ import annotations

from pathlib import Path

from engine.testing import TreeHarness

ASK_TWICE = """\
name: ask_twice
rate_hz: 10
root:
  Sequence:
    - OnEvent: {key: /speech/heard}
    - Say: {text: "Say it again"}
    - WaitForEvent: {key: /speech/heard, seconds: 5}
    - Say: {text: "Thank you"}
"""

TWO_RULES = """\
name: two_rules
rate_hz: 10
root:
  Selector:
    - Sequence:
        - OnEvent: {key: /speech/heard, equals: bye}
        - Say: {text: "Goodbye"}
    - Sequence:
        - OnEvent: {key: /speech/heard, equals: hi}
        - Say: {text: "Hello"}
"""


def robot_with(tmp_path: Path, text: str) -> TreeHarness:
    tree = tmp_path / "tree.yaml"
    tree.write_text(text, encoding="utf-8")
    return TreeHarness.from_file(tree)


def test_the_answer_a_wait_took_does_not_start_the_round_again(tmp_path: Path) -> None:
    robot = robot_with(tmp_path, ASK_TWICE)
    robot.set("/speech/heard", "hello")
    robot.advance(3.0)
    robot.set("/speech/heard", "hello again")  # taken by the wait
    robot.advance(10.0)
    assert robot.said == ["Say it again", "Thank you"]  # not "Say it again" once more

    robot.set("/speech/heard", "hello once more")  # new words start a new round
    robot.advance(3.0)
    assert robot.said == ["Say it again", "Thank you", "Say it again"]


def test_a_round_halted_and_let_go_lets_go_of_what_it_took(tmp_path: Path) -> None:
    robot = robot_with(tmp_path, ASK_TWICE)
    robot.set("/speech/heard", "hello")
    robot.advance(3.0)
    robot.set("/speech/heard", "hello again")
    robot.tick(2)
    assert robot.said == ["Say it again", "Thank you"]  # "Thank you" is being said

    robot.running.halt("a person spoke over it")
    robot.advance(10.0)
    assert robot.said == ["Say it again", "Thank you"]


def test_an_event_one_rule_passed_by_is_still_new_to_the_other(tmp_path: Path) -> None:
    robot = robot_with(tmp_path, TWO_RULES)
    robot.set("/speech/heard", "hi")
    robot.set("/speech/heard", "bye")  # both come before the tree's next tick
    robot.advance(10.0)
    # the first rule looked past "hi" to take "bye"; "hi" is still the second rule's
    assert robot.said == ["Goodbye", "Hello"]
