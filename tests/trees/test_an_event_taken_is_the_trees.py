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


ASK_TWICE_AGAIN = ASK_TWICE.replace(
    "rate_hz: 10\n", "rate_hz: 10\nwhen_interrupted: try_again\nwait_for_turn_s: 2\n"
)

PATS = """\
name: pats
rate_hz: 10
root:
  Selector:
    - Sequence:
        - OnTouch: {except_pads: [chest]}
        - Say: {text: "Thanks for the pat"}
    - Sequence:
        - OnTouch: {pads: [chest]}
        - Say: {text: "A hug!"}
"""


def test_a_round_tried_again_does_not_answer_what_the_round_before_took(tmp_path: Path) -> None:
    robot = robot_with(tmp_path, ASK_TWICE_AGAIN)
    robot.set("/speech/heard", "hello")
    robot.advance(3.0)
    robot.set("/speech/heard", "again")  # taken by the wait: the round is over
    robot.tick(1)
    robot.set("/speech/heard", "third")  # a new round begins on it...
    robot.tick(1)
    robot.running.halt("a hug interrupted it", tried_again=True)  # ...and is cut short
    robot.running.try_again()
    robot.advance(20.0)
    assert robot.said == ["Say it again", "Thank you", "Say it again", "Say it again"]


def test_a_pat_one_rule_leaves_to_others_is_still_the_other_rule_s(tmp_path: Path) -> None:
    robot = robot_with(tmp_path, PATS)
    robot.tick(2)
    robot.set("/sensors/touch/pat", "chest")  # both hands at once: a chest pat...
    robot.set("/sensors/touch/pat", "back")  # ...and a back pat, before the next tick
    robot.advance(10.0)
    assert sorted(robot.said) == ["A hug!", "Thanks for the pat"]


def test_what_a_tree_took_is_neither_unread_nor_missed(tmp_path: Path) -> None:
    robot = robot_with(tmp_path, ASK_TWICE)
    robot.set("/speech/heard", "one")
    robot.advance(3.0)
    robot.set("/speech/heard", "two")  # the wait took it
    robot.tick(1)
    robot.set("/speech/heard", "three")
    robot.blackboard.commit()
    # what a pause or the session's end reports as not carried out
    assert robot.running.events.take_unread("/speech/heard") == ["three"]

    for n in range(32):  # a burst: "two" leaves the key's last 32, and was the tree's
        robot.set("/speech/heard", f"burst {n}")
    robot.tick(1)
    assert robot.node_warnings == []


GATED = """\
name: greet
rate_hz: 10
root:
  Selector:
    - Sequence:
        - Check: {key: /sensors/touch/any, equals: true}
        - OnEvent: {key: /speech/heard, equals: "stop"}
        - Say: {text: "Stopping"}
    - Sequence:
        - OnEvent: {key: /speech/heard, one_of: ["hello", "hi"]}
        - Say: {text: "Hello to you"}
"""


def test_a_reloaded_tree_does_not_answer_again_what_the_old_version_took(
    tmp_path: Path,
) -> None:
    # the first rule is never reached (its Check fails), so its reader lags behind
    # "chatter", which no rule took: the new version reads on from there, past "hello"
    robot = robot_with(tmp_path, GATED)
    robot.tick(2)
    robot.set("/speech/heard", "chatter")
    robot.set("/speech/heard", "hello")
    robot.advance(5.0)
    definition = robot.running.definition  # the therapist saves the file: a reload
    robot.running.swap(definition, definition.build(robot.context), keep_events=True)
    robot.advance(5.0)
    assert robot.said == ["Hello to you"]
