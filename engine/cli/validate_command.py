"""Check YAML files: trees, subtrees, profiles, dialogs, scenarios and robot configs.

Give files or folders (searched recursively for *.yaml). Prints "ok" when everything is
valid; otherwise every problem as file:line:column: message (hint), and exits 1.
The checks are those ``vest run`` makes before it starts: trees are checked against the
robot config (--hardware, default examples/robots/sim.yaml: its devices, its 12 touch
pads), the dialogs of a folder together (two with one name), scenarios against the robot.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from engine.buttons.button_file import ButtonBoard, load_buttons
from engine.cli.output import tell
from engine.cli.robot_checks import check_on_robot, check_scenario_events, list_lengths
from engine.cli.run_inputs import (
    DEFAULT_BUTTONS,
    DEFAULT_DIALOGS,
    DEFAULT_HARDWARE,
    button_warnings,
    check_presses,
    default_buttons,
    dialogs_folder,
    found,
    load_checked_buttons,
    load_config,
    resolve_profile,
    robot_catalogue,
)
from engine.dialogs.library import DialogLibrary, check_dialog, find_dialogs_folder
from engine.files.parsed_files import ParsedFiles
from engine.files.problems import LoadError, Mark, Problem, Problems
from engine.files.yaml_source import YMap, YScalar
from engine.hardware.config import RobotConfig
from engine.loader.substitution import Profile, load_profile, undeclared_params
from engine.loader.tree_checks import (
    counting_warnings,
    spoken_quote_warnings,
    variable_problems,
)
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import TreeLoader, shown_path
from engine.loader.tree_resources import collisions
from engine.nodes.registry import NodeRegistry, default_registry
from engine.runtime.robot import declared_beside, tree_files
from engine.scenario.scenario_file import load_scenario
from engine.values.param_problems import did_you_mean


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("paths", nargs="+", type=Path, metavar="PATH", help="YAML files or folders")
    parser.add_argument(
        "--dialogs",
        type=Path,
        default=None,
        help="dialogs folder (default: the nearest dialogs/ above each file)",
    )
    parser.add_argument(
        "--profile",
        default=None,
        help="check the trees with this profile: a file, or a name in trees/profiles/ "
        "(child, adult), as vest run takes it",
    )
    parser.add_argument(
        "--hardware",
        type=Path,
        default=None,
        metavar="CONFIG",
        help=f"robot config the trees and scenarios run on (default: {DEFAULT_HARDWARE} "
        "when there is one)",
    )
    parser.add_argument(
        "--buttons",
        type=Path,
        default=None,
        metavar="FILE",
        help=f"the buttons scenarios press (default: {DEFAULT_BUTTONS} when there is one)",
    )


def yaml_files(paths: list[Path]) -> list[Path]:
    files: list[Path] = []
    for path in paths:
        if path.is_dir():
            files.extend(
                sorted(
                    p
                    for p in path.rglob("*.y*ml")
                    if not any(part.startswith(".") for part in p.parts)
                )
            )
        elif path.exists():
            files.append(path)
    return files


def kind_of(document: object) -> str | None:
    if not isinstance(document, YMap):
        return None
    if "root" in document or "rate_hz" in document or did_you_mean("root", list(document.entries)):
        return "tree"
    if "profile" in document:
        return "profile"
    if "rules" in document or "dialog" in document:
        return "dialog"
    if "events" in document or "duration_s" in document:
        return "scenario"
    if "devices" in document or "buses" in document:
        return "robot config"
    if "buttons" in document:
        return "buttons"
    return None


FOLDER_KINDS = {
    "trees": "tree",
    "parts": "tree",
    "profiles": "profile",
    "buttons": "buttons",
    "dialogs": "dialog",
}
"""What ``vest run`` reads every file of a folder so named as."""


def folder_kind_problem(path: Path, kind: str | None, where: Mark) -> Problem | None:
    """A file whose kind is not what ``vest run`` reads its folder as (a tree saved into
    dialogs/, a dialog into trees/), or None."""
    expected = FOLDER_KINDS.get(path.parent.name)
    if expected is None or kind == expected or kind is None:
        return None
    return Problem(
        where,
        f"a {kind} in {path.parent.name}/: vest run reads every file there as a {expected}",
        f"move it where {kind}s go" if kind != "tree" else "move it to trees/",
    )


class Validator:
    """Checks files one by one with the checks ``vest run`` makes (engine.cli.run_inputs)."""

    def __init__(
        self,
        registry: NodeRegistry,
        config: RobotConfig | None,
        dialogs_dir: Path | None,
        problems: Problems | None = None,
    ) -> None:
        self.registry = registry
        self.config = config
        self.catalogue = robot_catalogue(config, registry)
        self.lengths = list_lengths(config)
        self.dialogs_dir = dialogs_dir
        self.problems = problems if problems is not None else Problems()
        self._dialogs: dict[Path, DialogLibrary | None] = {}
        self.profile: Profile | None = None
        """The profile trees are checked with (``--profile``), as ``vest run`` applies it."""
        self.declared: set[str] = set()
        """Parameters the trees checked so far declare."""
        self.files = ParsedFiles()
        """Each file is parsed once, however many checks look at it."""
        self.buttons_file: Path | None = None
        self.boards: list[ButtonBoard] = []
        """The button files checked (their conditions are checked against the trees)."""
        self.default_dialogs: Path | None = None
        """The dialogs a tree with no dialogs folder of its own uses (as ``vest run``)."""
        """The buttons a scenario's presses are checked against (--buttons, else the
        default)."""
        self.trees: list[TreeDefinition] = []
        """The trees checked, to find those that would take turns by chance."""
        self.inside: Path | None = None
        """Files outside this folder are never read (the editor's folder), None: any."""

    def dialogs_for(self, path: Path) -> DialogLibrary | None:
        """The dialogs a tree at ``path`` uses (none when there is no dialogs folder, as in
        ``vest run``), or None when they have problems of their own (told once)."""
        folder = self.dialogs_dir or find_dialogs_folder(path) or self.default_dialogs
        if folder is None or (
            self.inside is not None and not folder.resolve().is_relative_to(self.inside.resolve())
        ):
            return DialogLibrary()  # none, or above the folder being edited: not read
        return self.dialog_library(folder)

    def dialog_library(self, folder: Path) -> DialogLibrary | None:
        """The folder's dialogs loaded as ``vest run`` loads them (so two dialogs with one
        name are found), once per folder however it is named."""
        key = folder.resolve()
        if key not in self._dialogs:
            try:
                self._dialogs[key] = DialogLibrary.from_folder(
                    folder, self.catalogue, inside=self.inside
                )
            except LoadError as error:
                self.problems.extend(error.problems)
                self._dialogs[key] = None
        return self._dialogs[key]

    def is_dialogs_folder(self, folder: Path) -> bool:
        given = self.dialogs_dir is not None and folder.resolve() == self.dialogs_dir.resolve()
        return given or folder.name == DEFAULT_DIALOGS.name

    def loader_for(self, path: Path, profile: Profile | None = None) -> TreeLoader:
        """A loader for the tree at ``path`` with ``profile`` (default: the one given)."""
        return TreeLoader(
            self.registry,
            self.catalogue,
            dialogs=self.dialogs_for(path),
            profile=profile or self.profile,
            files=self.files,
        )

    def check(self, path: Path) -> None:
        try:
            document = self.files.load(path, shown_path(path))
        except LoadError as error:
            self.problems.extend(error.problems)
            return
        kind = kind_of(document)
        where = document.mark if document is not None else Mark(shown_path(path), 1, 1)
        misplaced = folder_kind_problem(path, kind, where)
        if misplaced is not None:
            self.problems.add(misplaced.mark, misplaced.message, misplaced.hint)
            return  # read as what it is not, it says nothing more worth reading
        try:
            if kind == "tree":
                definition = self.loader_for(path).load(path)
                self.trees.append(definition)
                self.declared |= definition.declared_params
                self.problems.extend(check_on_robot(definition, self.config, self.lengths))
            elif kind == "profile":
                self.check_profile(path)
            elif kind == "dialog" and self.is_dialogs_folder(path.parent):
                self.dialog_library(path.parent)
            elif kind == "dialog":  # a dialog kept elsewhere is checked on its own
                check_dialog(document, str(path), self.catalogue, default_name=path.stem)
            elif kind == "scenario":
                scenario = load_scenario(path)
                if self.config is not None:
                    self.problems.extend(check_scenario_events(scenario.events, self.config))
                buttons = self.buttons_file or default_buttons()
                board = self.buttons(buttons) if buttons is not None else None
                self.problems.extend(check_presses(scenario.events, board, buttons))
            elif kind == "robot config":
                load_config(path, self.problems)
            elif kind == "buttons":
                board = load_checked_buttons(
                    path, self.loader_for(path), self.config, self.problems
                )
                if board is not None:
                    self.boards.append(board)
            else:
                where = document.mark if document is not None else Mark(str(path), 1, 1)
                self.problems.add(
                    where,
                    "cannot tell what this file is",
                    "a tree has 'root:', a profile 'profile:', a dialog 'rules:', "
                    "a scenario 'events:', a robot config 'devices:'",
                )
        except LoadError as error:
            self.problems.extend(error.problems)

    def check_profile(self, path: Path) -> None:
        """A profile must fit the trees beside it: known names, values of the right kind."""
        profile = load_profile(path)
        trees_folder = path.parent.parent
        for tree in tree_files([trees_folder]):
            try:
                self.loader_for(tree, profile).load(tree)
            except LoadError as error:  # the tree's own problems come when it is validated
                self.problems.extend([p for p in error.problems if p.mark.file == str(path)])
        declared = declared_beside(path)
        self.problems.extend(undeclared_params(profile, declared, f"{trees_folder}/"))

    def buttons(self, path: Path) -> ButtonBoard | None:
        """The button file a scenario's presses are checked against (its own problems are
        told when it is validated itself)."""
        try:
            return load_buttons(path, self.loader_for(path))
        except LoadError:
            return None

    def check_tree_names(self, files: list[Path]) -> None:
        """Two trees of one folder run together, so their names must differ."""
        seen: dict[tuple[Path, str], Path] = {}
        for path in files:
            try:
                document = self.files.load(path, shown_path(path))
            except LoadError:
                continue
            if kind_of(document) != "tree" or path.parent.name in ("parts", "profiles"):
                continue
            assert isinstance(document, YMap)
            raw = document.get("name")
            name = str(raw.value) if isinstance(raw, YScalar) and raw.value else path.stem
            key = (path.parent.resolve(), name)
            if key in seen:
                where = raw.mark if raw is not None else Mark(str(path), 1, 1)
                self.problems.add(
                    where, f"two trees are named {name!r} (also {seen[key]})", "rename one"
                )
            else:
                seen[key] = path


def main(args: argparse.Namespace) -> int:
    files = yaml_files(args.paths)
    problems = Problems()
    default = found(DEFAULT_HARDWARE)
    hardware = args.hardware or (default if default.is_file() else None)
    config = load_config(hardware, problems) if hardware is not None else None
    if hardware is None:  # say which checks were skipped, never a silent "ok"
        tell(
            f"note: no robot config here ({DEFAULT_HARDWARE} is missing): pads, joints, "
            "devices and safety were not checked; give --hardware CONFIG"
        )
    dialogs = dialogs_folder(args.dialogs) if args.dialogs is not None else None
    validator = Validator(default_registry(), config, dialogs, problems)
    # as vest run: a dialogs folder named among the paths, else the one it would use
    named = [p for p in args.paths if p.is_dir() and p.name == DEFAULT_DIALOGS.name]
    validator.default_dialogs = named[0] if named else dialogs_folder(None)
    validator.buttons_file = args.buttons
    profile = resolve_profile(args.profile, args.paths)
    if profile is not None:
        try:
            validator.profile = load_profile(profile)
        except LoadError as error:
            problems.extend(error.problems)
    for path in args.paths:
        if not path.exists():
            validator.problems.add(Mark(str(path), 1, 1), "no such file or folder")
    for path in files:
        validator.check(path)
    validator.check_tree_names(files)
    if validator.profile is not None and profile is not None and validator.declared:
        # as vest run: the profile sets only parameters the trees (or those beside it)
        # declare; told once the trees load (a tree that failed has declared nothing)
        where = (
            f"{profile.parent.parent}/" if profile.parent.name == "profiles" else "the trees given"
        )
        declared = validator.declared | declared_beside(profile)
        if not problems:
            problems.extend(undeclared_params(validator.profile, declared, where))
    run_together = [t for t in validator.trees if t.path.parent.name != "parts"]
    problems.extend(variable_problems(run_together, validator.catalogue))
    if validator.problems:
        # a file met twice (a dialog beside its tree, the robot config named) is told once
        raise LoadError(list(dict.fromkeys(validator.problems.items)))
    if not files:
        raise LoadError([Problem(Mark(str(args.paths[0]), 1, 1), "no YAML files found")])
    warnings = turn_warnings(run_together) + spoken_quote_warnings(run_together)
    warnings += counting_warnings(run_together)
    if run_together:  # as vest run warns: a button shown only while a missing tree runs
        names = [tree.name for tree in run_together]
        for board in validator.boards:
            warnings += button_warnings(board, names)
    for warning in dict.fromkeys(warnings):  # a file named twice is told once
        tell(warning)
    print(f"ok: {len(files)} file{'s' if len(files) != 1 else ''}")
    return 0


def turn_warnings(trees: list[TreeDefinition]) -> list[str]:
    """Trees run together that can want the same speaker, LEDs or joint at the same
    priority, each pair as a warning line; and trees that would try again at once, when
    the tree that cut them short is still at it."""
    warnings = [f"warning: {shown_path(c.second.path)}: {c.describe()}" for c in collisions(trees)]
    for tree in trees:
        if tree.when_interrupted == "try_again" and tree.wait_for_turn_s <= 0:
            warnings.append(
                f"warning: {shown_path(tree.path)}: when_interrupted: try_again starts the "
                "round again while the tree that cut it short still speaks or moves, and "
                "with wait_for_turn_s: 0 its actions let go at once (give it "
                "wait_for_turn_s: 3, say)"
            )
    return warnings
