"""What `vest edit` runs for the page: the checks a therapist sees as they type (those of
`vest validate`, on the text being edited in its file's place among the folder's others:
its subtrees, its dialogs, the robot's pads and joints; nothing written) and a try of the
tree on the simulated vest with one event (a pat, a squeeze, words said, a wave)."""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import yaml

from engine.cli.run_inputs import robot_catalogue
from engine.cli.validate_command import Validator, kind_of
from engine.dialogs.library import check_dialog
from engine.files.parsed_files import ParsedFiles
from engine.files.problems import LoadError, Problem, Problems
from engine.files.yaml_source import YValue, parse_yaml, resolved
from engine.hardware.config import RobotConfig
from engine.loader.tree_checks import variable_problems
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import shown_path
from engine.nodes.registry import NodeRegistry


class _Overlaid(ParsedFiles):
    """The folder's files, but one of them read from the text being edited."""

    def __init__(self, path: Path, text: str) -> None:
        super().__init__()
        self.path, self.text = resolved(path), text

    def load(self, path: Path, shown: str | None = None) -> YValue | None:
        if resolved(path) == self.path:
            return parse_yaml(self.text, shown or str(path))
        return super().load(path, shown)


class ValidateChecks:
    """:class:`~engine.editor.workspace.Checks` as ``vest validate`` makes them, for trees
    in ``folder`` on the robot of ``config`` (None: pads, joints and devices unchecked)."""

    def __init__(self, folder: Path, registry: NodeRegistry, config: RobotConfig | None) -> None:
        self.folder, self.registry, self.config = folder, registry, config
        self.files = ParsedFiles()
        self.catalogue = robot_catalogue(config, registry)

    def kind_of(self, path: Path) -> str:
        try:
            kind = kind_of(self.files.load(path)) or "other"
        except LoadError:
            return "unreadable"
        return "subtree" if kind == "tree" and path.parent.name == "parts" else kind

    def check(self, path: Path, text: str) -> tuple[list[Problem], TreeDefinition | None]:
        problems = Problems()
        try:
            document = parse_yaml(text, shown_path(path))
        except LoadError as error:
            return error.problems, None
        if kind_of(document) == "dialog":  # checked from the text, not the folder's copy
            try:
                check_dialog(document, shown_path(path), self.catalogue, default_name=path.stem)
            except LoadError as error:
                return error.problems, None
            return [], None
        validator = Validator(self.registry, self.config, None, problems)
        validator.files = _Overlaid(path, text)
        dialogs = self.folder / "dialogs"
        validator.default_dialogs = dialogs if dialogs.is_dir() else None
        validator.check(path)
        edited = validator.trees[0] if validator.trees else None
        for other in self._trees_beside(path):  # a subtree's change is checked where it is used
            validator.check(other)
        run_together = [tree for tree in validator.trees if tree.path.parent.name != "parts"]
        problems.extend(variable_problems(run_together, self.catalogue))
        return list(dict.fromkeys(problems.items)), edited

    def _trees_beside(self, path: Path) -> list[Path]:
        """The folder's other trees (not parts, profiles or buttons), when ``path`` is one
        of its trees or parts: `vest validate trees/` checks them together."""
        trees = (self.folder / "trees").resolve()
        if not resolved(path).is_relative_to(trees):
            return []
        return [
            other
            for other in sorted(trees.glob("*.y*ml"))
            if resolved(other) != resolved(path) and self.kind_of(other) == "tree"
        ]


TRY_AT_S = 1.0
TRY_FOR_S = 8.0
"""A try: the event at 1 s, the tree watched until 8 s (a cooldown's rest, a slow arm)."""
TRY_TIMEOUT_S = 60.0
MAX_SAID = 200
VEST = "import sys; from engine.cli import main; sys.exit(main())"


class TryError(ValueError):
    """A try the page asked for that cannot be made, in words."""


def tried_event(asked: object, pads: list[str]) -> dict[str, object]:
    """The scenario event the page asked for: ``{"kind": "pat", "pad": ...}``,
    ``{"kind": "squeeze"}``, ``{"kind": "say", "text": ...}`` or ``{"kind": "wave"}``."""
    if not isinstance(asked, dict):
        raise TryError("event: a pat, a squeeze, a phrase said or a wave")
    kind = asked.get("kind")
    if kind == "pat":
        pad = asked.get("pad")
        if pad not in pads:
            raise TryError(f"no pad {pad!r} on this robot (pads: {', '.join(pads)})")
        return {"at": TRY_AT_S, "touch": {"pad": pad, "seconds": 0.3}}
    if kind == "squeeze":
        return {"at": TRY_AT_S, "squeeze": {"left_n": 6.0, "right_n": 6.0, "seconds": 2.0}}
    if kind == "say":
        said = asked.get("text")
        if not isinstance(said, str) or not said.strip() or len(said) > MAX_SAID:
            raise TryError(f"say: the words a person says, 1 to {MAX_SAID} characters")
        return {"at": TRY_AT_S, "hear": {"text": said.strip()}}
    if kind == "wave":
        return {"at": TRY_AT_S, "gesture": "wave"}
    raise TryError("event: a pat, a squeeze, a phrase said or a wave")


class TryOnSimulatedVest:
    """Runs a tree being edited on the simulated vest, on a virtual clock, with one event:
    ``vest run --fast --speech text`` in a process of its own (a tree that hangs or fails
    cannot take the editor with it), on a copy of the folder's trees (its subtrees), the
    folder's dialogs and ``hardware``. Its timeline, in sentences, is the answer."""

    def __init__(self, folder: Path, hardware: Path | None, pads: list[str]) -> None:
        self.folder, self.hardware, self.pads = folder, hardware, pads
        self._one_at_a_time = threading.Lock()  # each try is a whole vest run

    def __call__(self, name: str, text: str, asked: object) -> list[str]:
        """The timeline of ``text`` (the file ``name``) tried with the event ``asked``;
        TryError (a ValueError) for an event that cannot be or a run that failed."""
        event = tried_event(asked, self.pads)
        if not self._one_at_a_time.acquire(blocking=False):
            raise TryError("another try is running: wait for its answer")
        try:
            return self._tried(name, text, event)
        finally:
            self._one_at_a_time.release()

    def _tried(self, name: str, text: str, event: dict[str, object]) -> list[str]:
        with tempfile.TemporaryDirectory(prefix="vest-try-") as scratch:
            copy = Path(scratch) / "folder"
            trees = self.folder / "trees"
            if trees.is_dir():  # a link leading out of the folder is not followed
                inside = resolved(self.folder)
                shutil.copytree(
                    trees,
                    copy / "trees",
                    ignore=lambda at, names: [
                        name
                        for name in names
                        if not resolved(Path(at) / name).is_relative_to(inside)
                    ],
                )
            tried = copy / name
            tried.parent.mkdir(parents=True, exist_ok=True)
            tried.write_text(text, encoding="utf-8")
            scenario = Path(scratch) / "try.yaml"
            scenario.write_text(
                yaml.safe_dump({"duration_s": TRY_FOR_S, "events": [event]}), encoding="utf-8"
            )
            command = [sys.executable, "-c", VEST, "run", "--fast", "--speech", "text"]
            command += ["--trees", str(tried), "--scenario", str(scenario)]
            if (self.folder / "dialogs").is_dir():
                command += ["--dialogs", str(self.folder / "dialogs")]
            if self.hardware is not None:
                command += ["--hardware", str(self.hardware)]
            try:
                done = subprocess.run(
                    command, capture_output=True, text=True, timeout=TRY_TIMEOUT_S, check=False
                )
            except subprocess.TimeoutExpired:
                raise TryError(f"the try ran over {TRY_TIMEOUT_S:g} s and was stopped") from None
        if done.returncode != 0:
            said = done.stderr.strip().splitlines()
            raise TryError(said[-1] if said else f"vest run ended with {done.returncode}")
        timeline = done.stdout.split("\n\n", 1)[0].splitlines()[1:]  # after its heading
        return [_sentence(line) for line in timeline if line.strip()]


def _sentence(line: str) -> str:
    """``"    1.00  tickles   says ..."`` as ``"1.00 s tickles: says ..."``."""
    at, who, what = [*line.split(None, 2), "", ""][:3]
    return f"{at} s {who}: {what}"


HEAR_TIMEOUT_S = 300.0


class HearCheck:
    """`vest dialogs check --quick` on a dialog as it is on the page: each phrase said once
    by the robot's neural voice and heard as the robot hears (a process of its own, about
    20 s for the shipped dialogs). Its lines are the answer, the file named as the page
    names it."""

    def __call__(self, name: str, text: str) -> list[str]:
        with tempfile.TemporaryDirectory(prefix="vest-hear-") as scratch:
            checked = Path(scratch) / Path(name).name
            checked.write_text(text, encoding="utf-8")
            command = [sys.executable, "-c", VEST, "dialogs", "check", "--quick", str(checked)]
            try:
                done = subprocess.run(
                    command, capture_output=True, text=True, timeout=HEAR_TIMEOUT_S, check=False
                )
            except subprocess.TimeoutExpired:
                raise TryError(f"the check ran over {HEAR_TIMEOUT_S:g} s and was stopped") from None
            said = (done.stdout + done.stderr).replace(str(checked), name)
        if done.returncode not in (0, 1):  # 1: it found problems, which are the answer
            lines = said.strip().splitlines()
            raise TryError(lines[-1] if lines else f"the check ended with {done.returncode}")
        return [line for line in said.splitlines() if line.strip()]
