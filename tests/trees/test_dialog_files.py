"""A therapist's own dialog file: answers naming any sensor, phrases in any script, and
concepts that would expand without end.

Each test writes a dialog beside a tree like trees/dialog.yaml (OnEvent on
/speech/heard -> Reply) and drives it with the TreeHarness.
"""

from __future__ import annotations

import textwrap
import time
from pathlib import Path

import pytest
from py_trees.common import Status

from engine.blackboard.catalogue import default_catalogue
from engine.dialogs.library import load_dialog
from engine.files.problems import LoadError
from engine.testing import TreeHarness

TREE = """\
name: dialog
root:
  Sequence:
    - OnEvent: {key: /speech/heard, save_as: /vars/heard}
    - Reply: {heard: /vars/heard}
"""


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text), encoding="utf-8")
    return path


def robot_with(folder: Path, dialog: str) -> TreeHarness:
    write(folder, "dialogs/default.yaml", dialog)
    return TreeHarness.from_file(write(folder, "trees/dialog.yaml", TREE))


def dialog_problems(folder: Path, text: str) -> list[str]:
    path = write(folder, "d.yaml", text)
    with pytest.raises(LoadError) as caught:
        load_dialog(path, default_catalogue(), "d.yaml")
    return [str(problem) for problem in caught.value.problems]


# -- answers filled from any blackboard key ----------------------------------------------
FORCE_AND_DISTANCE = """\
dialog: default
rules:
  - hear: ["how hard"]
    say: "You pressed with {force_left_n:.0f} newtons"
  - hear: ["how far"]
    read: ultrasound
    say: "Something is {ultrasound_cm:.0f} cm away"
fallback: "I felt {/vars/mood}"
"""


def test_an_answer_may_name_a_sensor_the_rule_does_not_read(tmp_path: Path) -> None:
    robot = robot_with(tmp_path, FORCE_AND_DISTANCE)
    robot.set("/sensors/force/left_n", 6.0)
    robot.set("/speech/heard", "how hard")
    robot.tick()
    assert robot.said == ["You pressed with 6 newtons"]
    assert robot.node_errors == []


def test_a_fallback_may_name_a_tree_variable(tmp_path: Path) -> None:
    robot = robot_with(tmp_path, FORCE_AND_DISTANCE)
    robot.set("/vars/mood", "happy")
    robot.set("/speech/heard", "sing a song")
    robot.tick()
    assert robot.said == ["I felt happy"]


def test_an_answer_whose_field_has_no_value_fails_in_words_not_with_an_error(
    tmp_path: Path,
) -> None:
    robot = robot_with(tmp_path, FORCE_AND_DISTANCE)  # nothing in front: no distance
    robot.set("/speech/heard", "how far")
    # OnEvent: SUCCESS, Reply: FAILURE (reads, then cannot fill the answer) -> FAILURE
    assert robot.tick() == Status.FAILURE
    assert robot.said == []
    assert robot.node_errors == []
    reply = robot.tree.root.children[1]
    assert reply.feedback_message == "could not answer: /sensors/ultrasound/cm has no value yet"


# -- phrases in any script -------------------------------------------------------------------
WORLD = """\
dialog: default
rules:
  - hear: ["как тебя зовут"]
    say: "Меня зовут Эйч Би Эс"
  - hear: ["नमस्ते रोबोट"]
    say: "नमस्ते"
  - hear: ["¿Cómo estás?"]
    say: "Muy bien"
  - hear: ["你好"]
    say: "你好!"
"""


@pytest.mark.parametrize(
    ("heard", "answer"),
    [
        ("Как тебя зовут?", "Меня зовут Эйч Би Эс"),
        ("नमस्ते, रोबोट!", "नमस्ते"),
        ("cómo estás", "Muy bien"),
        ("CÓMO ESTÁS", "Muy bien"),
        ("你好", "你好!"),
    ],
)
def test_phrases_in_any_script_are_heard(tmp_path: Path, heard: str, answer: str) -> None:
    robot = robot_with(tmp_path, WORLD)
    robot.set("/speech/heard", heard)
    robot.tick()
    assert robot.said == [answer]


def test_a_phrase_of_punctuation_only_is_reported_where_it_is(tmp_path: Path) -> None:
    assert dialog_problems(
        tmp_path,
        """\
        dialog: d
        rules:
          - hear: ["hello", "!!!"]
            say: Hi
        """,
    ) == ["d.yaml:3:21: phrase '!!!' has no words (write it with letters or digits)"]


# -- concepts that multiply --------------------------------------------------------------------
FORTY = ", ".join(f"x{i}" for i in range(40))


def test_a_phrase_expanding_to_millions_is_refused_at_once(tmp_path: Path) -> None:
    started = time.process_time()
    problems = dialog_problems(
        tmp_path,
        f"""\
        dialog: d
        concepts:
          a: [{FORTY}]
        rules:
          - hear: ["~a ~a ~a ~a ~a"]
            say: ok
        """,
    )
    assert problems == [
        "d.yaml:5:12: phrase expands to 102400000 phrases, more than 200 "
        "(use fewer ~concepts in one phrase, or write several shorter phrases)"
    ]
    assert time.process_time() - started < 5  # not 100 million phrases built first


def test_a_dialog_whose_phrases_together_expand_too_far_is_refused_at_the_phrase(
    tmp_path: Path,
) -> None:
    rules = "".join(f'  - hear: ["~a ~b {i}"]\n    say: ok\n' for i in range(20))
    problems = dialog_problems(
        tmp_path,
        "dialog: d\nconcepts:\n"
        f"  a: [{', '.join(f'a{i}' for i in range(10))}]\n"
        f"  b: [{', '.join(f'b{i}' for i in range(15))}]\n"
        f"rules:\n{rules}",
    )
    # 150 phrases per rule: the 14th rule passes 2000
    assert problems == [
        "d.yaml:32:12: the dialog's phrases expand to more than 2000 phrases by here "
        "(use fewer ~concepts, or split the dialog in two)"
    ]


# -- follow-ups and rule ids ---------------------------------------------------------------
def test_a_follow_up_that_is_not_a_mapping_is_named_where_it_is(tmp_path: Path) -> None:
    problems = dialog_problems(
        tmp_path,
        """\
        dialog: d
        rules:
          - hear: ["do you like animals"]
            say: "Do you have a pet?"
            then: ["yes"]
        """,
    )
    assert problems == [
        "d.yaml:5:11: 'then' is a mapping with 'rules:' (and 'listen_s', 'otherwise')"
    ]


def test_a_follow_up_s_listening_time_must_be_a_positive_number(tmp_path: Path) -> None:
    problems = dialog_problems(
        tmp_path,
        """\
        dialog: d
        rules:
          - hear: ["do you like animals"]
            say: "Do you have a pet?"
            then:
              listen_s: -1
              rules:
                - hear: ["yes"]
                  say: "Lovely"
        """,
    )
    assert len(problems) == 1
    assert problems[0].startswith("d.yaml:6:17: 'listen_s' must be a number at least 1 ")


def test_two_rules_with_one_id_are_named_with_both_lines(tmp_path: Path) -> None:
    problems = dialog_problems(
        tmp_path,
        """\
        dialog: d
        rules:
          - id: pets
            hear: ["do you like animals"]
            say: "Do you have a pet?"
            then:
              rules:
                - id: pets
                  hear: ["yes"]
                  say: "Lovely"
        """,
    )
    assert problems == [
        "d.yaml:8:11: two rules have the id 'pets' (also line 3) (give one of them another 'id:')"
    ]


def test_follow_ups_nest_at_most_five_deep(tmp_path: Path) -> None:
    rule = 'hear: ["x{n}"]\n{pad}say: "y"\n{pad}then:\n{pad}  rules:\n{pad}    - '
    text, pad = "dialog: d\nrules:\n  - ", "    "
    for n in range(7):
        text += rule.format(n=n, pad=pad)
        pad += "      "
    text += 'hear: ["last"]\n' + pad + 'say: "end"\n'
    problems = dialog_problems(tmp_path, text)
    assert len(problems) == 1 and "follow-ups nest deeper than 5" in problems[0]


def test_a_follow_up_is_kept_for_the_next_utterance_only(tmp_path: Path) -> None:
    robot = robot_with(
        tmp_path,
        """\
        dialog: default
        rules:
          - hear: ["do you like animals"]
            say: "Do you have a pet?"
            then:
              rules:
                - hear: ["yes"]
                  say: "Lovely"
        fallback: "Pardon?"
        """,
    )
    for utterance in ("do you like animals", "banana", "yes"):
        robot.set("/speech/heard", utterance)
        robot.advance(1.0)
    assert robot.said == ["Do you have a pet?", "Pardon?", "Pardon?"]


def test_empty_lists_of_rules_or_phrases_are_named(tmp_path: Path) -> None:
    problems = dialog_problems(
        tmp_path,
        """\
        dialog: d
        rules:
          - hear: []
            say: "Hi"
            then: {rules: []}
        """,
    )
    assert problems == [
        "d.yaml:3:11: 'hear' is empty (list the phrases that trigger the rule)",
        "d.yaml:5:19: 'rules' is empty (add a hear/say rule)",
    ]


def test_follow_up_rules_without_ids_are_named_under_their_question(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "d.yaml",
        """\
        dialog: d
        rules:
          - hear: ["do you like animals"]
            say: "Do you have a pet?"
            then: {rules: [{hear: ["yes"], say: "Lovely"}]}
          - hear: ["do you like music"]
            say: "Do you play an instrument?"
            then: {rules: [{hear: ["yes"], say: "Great"}]}
        """,
    )
    dialog = load_dialog(path, default_catalogue(), "d.yaml")
    assert [rule.id for rule in dialog.all_rules()] == [
        "do you like animals",
        "do you like music",
        "do you like animals/yes",
        "do you like music/yes",
    ]


def test_a_phrase_two_rules_listen_for_is_refused_before_it_silently_answers_nothing(
    tmp_path: Path,
) -> None:
    problems = dialog_problems(
        tmp_path,
        """\
        dialog: d
        concepts:
          pet: ["dog", "cat"]
        rules:
          - id: name
            hear: ["what is your name"]
            say: "Robot"
          - id: pets
            hear: ["do you like ~pet", "what is your name"]
            say: "Yes"
            then:
              rules:
                - hear: ["do you like dog"]
                  say: "Dogs!"
        """,
    )
    # a follow-up is another conversation: its own rules may share the top level's phrases
    assert problems == [
        "d.yaml:8:5: rules 'name' (line 5) and 'pets' both listen for 'what is your name': "
        "said, it fits both and neither answers (keep the phrase in one rule)"
    ]


# -- asking instead of giving up ---------------------------------------------------------
def test_a_rule_that_confirms_in_a_dialog_with_nothing_to_say_to_a_no_is_refused(
    tmp_path: Path,
) -> None:
    problems = dialog_problems(
        tmp_path,
        """\
        dialog: d
        rules:
          - id: name
            hear: ["what is your name"]
            say: "I am Ro"
            confirm: "Did you ask my name?"
        """,
    )
    assert problems == [
        "d.yaml:3:5: rule 'name' asks to confirm, but the dialog says nothing to a no "
        "(add 'fallback:' or 'reprompt:' to the dialog)"
    ]


def test_an_empty_reprompt_list_and_a_confirm_that_is_not_text_are_named_where_they_are(
    tmp_path: Path,
) -> None:
    problems = dialog_problems(
        tmp_path,
        """\
        dialog: d
        rules:
          - hear: ["what is your name"]
            say: "I am Ro"
            confirm: [1, 2]
          - hear: ["how are you"]
            say: "Fine"
            confirm: ""
        reprompt: []
        fallback: "Sorry?"
        """,
    )
    assert problems == [
        "d.yaml:5:14: 'confirm' must be text, got a list (put it in quotes)",
        "d.yaml:8:14: 'confirm' is empty (write what the robot says)",
        "d.yaml:9:11: 'reprompt' is empty (list what the robot says instead)",
    ]
    problems = dialog_problems(
        tmp_path,
        """        dialog: d
        rules:
          - {hear: ["what is your name"], say: "I am Ro"}
        reprompt: ["Again?", 42]
        """,
    )
    assert problems == ["d.yaml:4:22: a 'reprompt' line must be text, got 42 (put it in quotes)"]


def test_a_dialog_in_another_language_confirms_with_its_own_yes_and_no(tmp_path: Path) -> None:
    robot = robot_with(
        tmp_path,
        """\
        dialog: default
        concepts:
          yes: ["oui", "ouais"]
          no: ["non"]
        rules:
          - hear: ["comment tu t'appelles"]
            say: "Je m'appelle Ro"
            confirm: "Tu demandes mon nom ?"
        reprompt: "Tu peux répéter plus lentement ?"
        """,
    )
    robot.set("/speech/heard", "comment toi appelles")
    robot.advance(1.0)
    robot.set("/speech/heard", "oui")
    robot.advance(1.0)
    robot.set("/speech/heard", "comment toi appelles")
    robot.advance(1.0)
    robot.set("/speech/heard", "non")
    robot.advance(1.0)
    assert robot.said == [
        "Tu demandes mon nom ?",
        "Je m'appelle Ro",
        "Tu demandes mon nom ?",
        "Tu peux répéter plus lentement ?",
    ]
