"""The command's own output: a full disk never ends in a traceback nor stops the robot,
text people wrote cannot forge timeline lines, and --json is strict JSON."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest

from engine.cli import main
from engine.cli.output import shown
from engine.cli.timeline import Timeline
from engine.session.events import ActionStarted
from engine.session.json_values import json_value

pytestmark = pytest.mark.realtime

ROOT = Path(__file__).resolve().parents[1]
VEST = [sys.executable, "-c", "from engine.cli import main; raise SystemExit(main())"]


def run_on_a_full_disk(*args: str) -> subprocess.CompletedProcess[str]:
    """``vest ARGS > /dev/full``: every write to standard output fails with ENOSPC."""
    with open("/dev/full", "w") as full:
        return subprocess.run(
            [*VEST, *args],
            cwd=ROOT,
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            check=False,
            timeout=120,
        )


class FullDisk:
    """A standard output on a full disk: every write fails, as /dev/full does."""

    def __init__(self) -> None:
        self.attempts = 0

    def write(self, text: str) -> int:
        self.attempts += 1
        raise OSError(28, "No space left on device")

    def flush(self) -> None:
        """Nothing is buffered."""


def record(text: str, tree: str = "hug", **args: Any) -> ActionStarted:
    return ActionStarted(1.5, 1, tree, "say", {"text": text, **args})


@pytest.mark.parametrize(
    "command",
    [
        ["validate", "trees/"],
        ["render", "trees/hug.yaml"],
        ["nodes"],
        ["keys"],
        ["schema"],
        ["devices"],
    ],
    ids=lambda command: command[0],
)
def test_a_command_whose_output_fails_says_so_in_one_line_and_exits_1(
    command: list[str],
) -> None:
    result = run_on_a_full_disk(*command)
    assert result.returncode == 1
    assert result.stderr.splitlines() == [
        f"vest {command[0]}: cannot write the output (No space left on device)"
    ]


@pytest.mark.parametrize("shape", [[], ["--json"]], ids=["lines", "json"])
def test_a_run_whose_timeline_fails_goes_on_to_the_end_and_says_so_once(shape: list[str]) -> None:
    result = run_on_a_full_disk("run", "--fast", "--duration", "6", *shape)
    assert result.returncode == 1  # the robot ran; what it did could not be written
    told = result.stderr.splitlines()
    assert told[0].startswith("vest run: loading the speech models")  # never silent
    assert told[1].startswith("speech: the hibari voice; hears with ")  # told at start-up
    assert told[2:] == [
        "vest run: cannot write the timeline (No space left on device); "
        "the robot carries on without it"
    ]


def test_a_timeline_on_a_full_disk_stops_writing_but_never_stops_the_robot() -> None:
    disk = FullDisk()
    stopped: list[bool] = []
    timeline = Timeline(disk, start_s=0.0, on_closed=lambda: stopped.append(True))  # type: ignore[arg-type]
    timeline.start()
    timeline.on_event(record("Thank you"))
    timeline.on_event(record("I love hugs!"))
    assert stopped == []  # the scheduler was not asked to stop
    assert disk.attempts == 1  # told once, then the timeline is given up
    assert timeline.write_error is not None


def test_spoken_text_with_a_newline_and_a_terminal_escape_stays_on_its_own_line() -> None:
    out = _Lines()
    timeline = Timeline(out, start_s=0.0)  # type: ignore[arg-type]
    forged = 'hi"\n    9.99  hug            says "I was never said\x1b[2J'
    timeline.on_event(record(forged, tree="evil\r\x1b]0;title\x07"))
    assert len(out.lines) == 1
    line = out.lines[0]
    assert "\n" not in line.rstrip("\n") and "\x1b" not in line and "\r" not in line
    assert "\\n    9.99  hug" in line
    assert "\\x1b[2J" in line
    assert line.startswith("    1.50  evil\\r\\x1b]0;title\\x07")


def test_ordinary_text_in_any_script_is_shown_as_written() -> None:
    for text in ("I love hugs!", "café, नमस्ते, 你好", "non\u00a0breaking space"):
        assert shown(text) == text
    assert shown("a\tb\\c\u2028d") == "a\\tb\\c\\u2028d"  # a backslash stays as written


def test_json_lines_are_strict_json_with_null_for_numbers_that_are_not_finite() -> None:
    out = _Lines()
    timeline = Timeline(out, start_s=0.0, as_json=True)  # type: ignore[arg-type]
    reading = ActionStarted(
        2.0,
        1,
        "iot_command",
        "report",
        {"id": "cmd-1", "result": {"c": float("nan"), "cm": [float("inf"), 1.5]}},
    )
    timeline.on_event(reading)

    def refuse(constant: str) -> None:
        raise AssertionError(f"{constant} is not JSON")

    shown_line = json.loads(out.lines[0], parse_constant=refuse)
    assert shown_line["args"]["result"] == {"c": None, "cm": [None, 1.5]}
    assert json_value({"ok": 1.0, "t": (-float("inf"),)}) == {"ok": 1.0, "t": [None]}


def test_a_tree_name_and_phrase_with_control_characters_are_escaped_in_a_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(ROOT)
    tree = tmp_path / "trees" / "sly.yaml"
    tree.parent.mkdir()
    tree.write_text(
        textwrap.dedent(
            """\
            name: "sly\\e[31m"
            rate_hz: 10
            root:
              Cooldown:
                seconds: 100
                child:
                  Say: {text: "one\\n    0.50  world          forged"}
            """
        )
    )
    assert main(["run", "--fast", "--trees", str(tree), "--duration", "1"]) == 0
    out = capsys.readouterr().out
    assert '    0.00  sly\\x1b[31m    says "one\\n    0.50  world          forged"' in out
    assert "\x1b" not in out
    assert "\n    0.50  world" not in out


class _Lines:
    """A standard output that keeps what was written, line by line."""

    def __init__(self) -> None:
        self.text = ""

    def write(self, text: str) -> int:
        self.text += text
        return len(text)

    def flush(self) -> None:
        """Nothing is buffered."""

    @property
    def lines(self) -> list[str]:
        return self.text.splitlines(keepends=True)
