"""Check YAML files: trees, subtrees, profiles, dialogs, scenarios and robot configs.

Give files or folders (searched recursively for *.yaml). Prints "ok" when everything is
valid; otherwise every problem as file:line:column: message (hint), and exits 1.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from engine.blackboard.catalogue import KeyCatalogue, default_catalogue
from engine.dialogs.library import DialogLibrary, check_dialog, find_dialogs_folder
from engine.files.problems import LoadError, Mark, Problem, Problems
from engine.files.yaml_source import YMap, YScalar, load_yaml
from engine.hardware.config import check_robot_config
from engine.loader.substitution import Profile, load_profile, undeclared_params
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import NodeRegistry, default_registry
from engine.runtime.robot import declared_beside, tree_files
from engine.scenario.scenario_file import check_scenario
from engine.values.params import did_you_mean

NAME = "validate"
HELP = "check trees, profiles, dialogs and scenarios"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("paths", nargs="+", type=Path, metavar="PATH", help="YAML files or folders")
    parser.add_argument(
        "--dialogs",
        type=Path,
        default=None,
        help="dialogs folder (default: the nearest dialogs/ above each file)",
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
    return None


class Validator:
    def __init__(
        self, registry: NodeRegistry, catalogue: KeyCatalogue, dialogs_dir: Path | None
    ) -> None:
        self.registry = registry
        self.catalogue = catalogue
        self.dialogs_dir = dialogs_dir
        self.problems = Problems()
        self._dialogs: dict[Path, DialogLibrary | None] = {}

    def dialogs_for(self, path: Path) -> DialogLibrary | None:
        folder = self.dialogs_dir or find_dialogs_folder(path)
        if folder is None:
            return None
        if folder not in self._dialogs:
            try:
                self._dialogs[folder] = DialogLibrary.from_folder(folder, self.catalogue)
            except LoadError as error:
                self.problems.extend(error.problems)
                self._dialogs[folder] = None
        return self._dialogs[folder]

    def loader_for(self, path: Path, profile: Profile | None = None) -> TreeLoader:
        return TreeLoader(
            self.registry, self.catalogue, dialogs=self.dialogs_for(path), profile=profile
        )

    def check(self, path: Path) -> None:
        try:
            document = load_yaml(path)
        except LoadError as error:
            self.problems.extend(error.problems)
            return
        kind = kind_of(document)
        try:
            if kind == "tree":
                self.loader_for(path).load(path)
            elif kind == "profile":
                self.check_profile(path)
            elif kind == "dialog":
                check_dialog(document, str(path), self.catalogue, default_name=path.stem)
            elif kind == "scenario":
                check_scenario(document, str(path), path)
            elif kind == "robot config":
                check_robot_config(document, str(path), path, catalogue=self.catalogue)
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

    def check_tree_names(self, files: list[Path]) -> None:
        """Two trees of one folder run together, so their names must differ."""
        seen: dict[tuple[Path, str], Path] = {}
        for path in files:
            try:
                document = load_yaml(path)
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
    validator = Validator(default_registry(), default_catalogue(), args.dialogs)
    for path in args.paths:
        if not path.exists():
            validator.problems.add(Mark(str(path), 1, 1), "no such file or folder")
    for path in files:
        validator.check(path)
    validator.check_tree_names(files)
    if validator.problems:
        raise LoadError(validator.problems.items)
    if not files:
        raise LoadError([Problem(Mark(str(args.paths[0]), 1, 1), "no YAML files found")])
    print(f"ok: {len(files)} file{'s' if len(files) != 1 else ''}")
    return 0
