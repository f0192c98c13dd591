"""The checks `vest edit` shows as a therapist types: those of `vest validate`, on the text
being edited in its file's place among the folder's others (its subtrees, the trees that
use it and run beside it, its dialogs, the robot's pads and joints), without writing it
anywhere. Only files inside the folder are read: a subtree that leads out of it (to the
site's consent.yaml, say) is a problem named by its path, never read."""

from __future__ import annotations

from pathlib import Path

from engine.cli.run_inputs import robot_catalogue
from engine.cli.validate_command import Validator, folder_kind_problem, kind_of
from engine.dialogs.library import OUTSIDE, check_dialog
from engine.files.parsed_files import ParsedFiles
from engine.files.problems import LoadError, Mark, Problem, Problems
from engine.files.yaml_source import YValue, parse_yaml, resolved
from engine.hardware.config import RobotConfig
from engine.loader.tree_checks import variable_problems
from engine.loader.tree_definition import TreeDefinition
from engine.loader.tree_file import shown_path
from engine.nodes.registry import NodeRegistry


class _InTheFolder(ParsedFiles):
    """The folder's files, none read from outside ``folder`` (a link, ``../``, an absolute
    path out: a problem named by its path)."""

    def __init__(self, folder: Path) -> None:
        super().__init__()
        self.folder = resolved(folder)

    def load(self, path: Path, shown: str | None = None) -> YValue | None:
        if not resolved(path).is_relative_to(self.folder):
            raise LoadError([Problem(Mark(shown or str(path), 1, 1), OUTSIDE, "keep it inside")])
        return super().load(path, shown)


class _Overlaid(_InTheFolder):
    """The folder's files, but one of them read from the text being edited."""

    def __init__(self, folder: Path, path: Path, text: str) -> None:
        super().__init__(folder)
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
        self.files = _InTheFolder(folder)
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
        kind = kind_of(document)
        where = document.mark if document is not None else Mark(shown_path(path), 1, 1)
        misplaced = folder_kind_problem(path, kind, where)
        if misplaced is not None:
            return [misplaced], None
        if kind == "dialog":  # checked from the text, not the folder's copy
            try:
                check_dialog(document, shown_path(path), self.catalogue, default_name=path.stem)
            except LoadError as error:
                return error.problems, None
            return [], None
        validator = Validator(self.registry, self.config, self.folder / "dialogs", problems)
        validator.files = _Overlaid(self.folder, path, text)
        validator.inside = self.folder  # its dialogs too: a link out is a problem, not read
        validator.check(path)
        edited = validator.trees[0] if validator.trees else None
        beside = self._trees_beside(path)
        for other in beside:  # a subtree's change is checked where it is used
            validator.check(other)
        validator.check_tree_names([*beside, path])  # trees run together: their names differ
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
            if resolved(other) != resolved(path)
            and resolved(other).is_relative_to(self.folder)
            and self.kind_of(other) == "tree"
        ]
