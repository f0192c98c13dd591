"""Tree files: validated whole into a :class:`TreeDefinition`, then built into py_trees.

A tree file::

    name: hug
    rate_hz: 20
    description: Hug back when both side pads are squeezed.
    params:
      threshold_n: 3.0
    root:
      Sequence:
        - Check: {key: /sensors/force/left_n, above: "${threshold_n}"}
        - ...

A node is a mapping with one key, its type. Composites take a list of children (or a
mapping with their options and ``children:``); decorators a mapping with their options and
``child:``; leaves a mapping of parameters. Every node accepts ``name:`` for display.
``Subtree: {file: parts/x.yaml, params: {...}}`` includes another tree file's root.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from engine.blackboard.catalogue import KeyCatalogue
from engine.dialogs.library import DialogLibrary
from engine.files.parsed_files import ParsedFiles
from engine.files.problems import LoadError, Mark, Problems
from engine.files.yaml_source import (
    YList,
    YMap,
    YScalar,
    YValue,
    describe,
    plain,
    resolved,
)
from engine.loader.node_arguments import node_arguments
from engine.loader.substitution import (
    ParamValue,
    Profile,
    check_override,
    read_params,
    substitute,
)
from engine.loader.tree_definition import NodeDefinition, TreeDefinition
from engine.loader.tree_settings import SETTINGS, read_setting, read_settings
from engine.nodes.registry import NodeRegistry
from engine.nodes.spec import NodeType
from engine.values.param_problems import CheckContext, did_you_mean

TOP_KEYS = ("name", "description", *(setting.name for setting in SETTINGS), "params", "root")
SUBTREE = "Subtree"


@dataclass
class _Seen:
    """What one load met on its way: the files read and the parameters they declare."""

    files: list[Path] = field(default_factory=list)
    declared: set[str] = field(default_factory=set)
    tried: list[Path] = field(default_factory=list)
    """Every file the load tried to read, found or not."""


def shown_path(path: Path, base: Path | None = None) -> str:
    """How messages name ``path``: relative to ``base`` (the working folder) when inside."""
    try:
        shown = str(resolved(path).relative_to(resolved(base or Path.cwd())))
    except ValueError:
        shown = str(path)
    return shown.replace("\0", "\\0")  # a NUL would cut the line a terminal shows


class TreeLoader:
    """Validates tree files against a registry, a key catalogue, dialogs and a profile."""

    def __init__(
        self,
        registry: NodeRegistry,
        catalogue: KeyCatalogue,
        *,
        dialogs: DialogLibrary | None = None,
        profile: Profile | None = None,
        root_dir: Path | None = None,
        files: ParsedFiles | None = None,
    ) -> None:
        self.registry = registry
        self.files = files or ParsedFiles()
        self.catalogue = catalogue
        self.dialogs = dialogs
        self.profile = profile
        self.root_dir = root_dir
        self.check_context = CheckContext(catalogue, dialogs)

    def shown(self, path: Path) -> str:
        """How messages name ``path``: relative to the working folder when inside it."""
        return shown_path(path, self.root_dir)

    def load(self, path: Path) -> TreeDefinition:
        """Validate the tree file at ``path``; LoadError listing every problem."""
        return self._load(path, _Seen())

    def load_watching(self, path: Path) -> tuple[TreeDefinition | LoadError, list[Path]]:
        """The tree (or why not) and every file the load read or tried to read: what hot
        reload watches, including a subtree a refused edit names that does not exist yet."""
        seen = _Seen()
        try:
            return self._load(path, seen), seen.tried
        except LoadError as error:
            return error, seen.tried

    def _load(self, path: Path, seen: _Seen) -> TreeDefinition:
        problems = Problems()
        document = self._read(path, problems, seen)
        if document is None:
            problems.raise_if_any()
            raise LoadError([])  # pragma: no cover - _read always reports why
        name = path.stem
        raw_name = document.get("name")
        if raw_name is not None:
            if (
                isinstance(raw_name, YScalar)
                and isinstance(raw_name.value, str)
                and raw_name.value.strip()
            ):
                name = raw_name.value.strip()
            else:
                problems.add(raw_name.mark, f"'name' must be text, got {describe(raw_name)}")
        params = self._params(document, problems, overrides=None, where="")
        settings = read_settings(document, params, problems, self.check_context)
        description = document.get("description")
        root = self._root(document, path, params, problems, [resolved(path)], seen)
        problems.raise_if_any()
        assert root is not None
        text = plain(description) if description is not None else ""
        return TreeDefinition(
            name,
            settings.rate_hz,
            str(text or ""),
            root,
            path,
            seen.files,
            frozenset(seen.declared),
            priority=settings.priority,
            wait_for_turn_s=settings.wait_for_turn_s,
            when_interrupted=settings.when_interrupted,
            wake_on=settings.wake_on,
            interruptible=settings.interruptible,
        )

    # -- file level -----------------------------------------------------------------------
    def _read(self, path: Path, problems: Problems, seen: _Seen) -> YMap | None:
        shown = self.shown(path)
        seen.tried.append(path)
        try:
            document = self.files.load(path, shown)
        except LoadError as error:
            problems.extend(error.problems)
            return None
        seen.files.append(path)
        if not isinstance(document, YMap):
            where = document.mark if document is not None else Mark(shown, 1, 1)
            problems.add(
                where,
                "a tree file is a mapping with 'name:', 'rate_hz:' and 'root:'",
                "see docs/therapist-guide.md",
            )
            return None
        problems.unknown_fields(document.key_marks, TOP_KEYS)
        declared = document.get("params")
        if isinstance(declared, YMap):
            seen.declared.update(declared.entries)
        return document

    def _params(
        self,
        document: YMap,
        problems: Problems,
        overrides: dict[str, ParamValue] | None,
        where: str,
    ) -> dict[str, ParamValue]:
        params = read_params(document.get("params"), problems)
        if self.profile is not None:
            for name, given in self.profile.params.items():
                if name in params and check_override(
                    name, params[name], given, problems, f"profile {self.profile.name!r}"
                ):
                    params[name] = given
        for name, given in (overrides or {}).items():
            if name not in params:
                problems.add(
                    given.source,
                    f"{where} passes unknown parameter {name!r}",
                    did_you_mean(name, list(params))
                    or "parameters: " + (", ".join(params) or "none"),
                )
            elif check_override(name, params[name], given, problems, where):
                params[name] = given
        return params

    def _root(
        self,
        document: YMap,
        path: Path,
        params: dict[str, ParamValue],
        problems: Problems,
        stack: list[Path],
        seen: _Seen,
    ) -> NodeDefinition | None:
        raw = document.get("root")
        if raw is None:
            problems.add(document.mark, "the tree has no 'root:'", "add root: with one node")
            return None
        return self._node(substitute(raw, params, problems), path, problems, stack, seen)

    # -- nodes ----------------------------------------------------------------------------
    def _node(
        self, raw: YValue, path: Path, problems: Problems, stack: list[Path], seen: _Seen
    ) -> NodeDefinition | None:
        misplaced = self._dedented_parameter(raw)
        if misplaced is not None:
            problems.add(*misplaced)
            return None
        if not isinstance(raw, YMap) or len(raw) != 1:
            got = (
                describe(raw)
                if not isinstance(raw, YMap)
                else (f"{len(raw)} keys ({', '.join(k for k, _ in raw.items()) or 'none'})")
            )
            problems.add(
                raw.mark,
                f"a node is a mapping with one key, its type; got {got}",
                "e.g. - Say: {text: hello}",
            )
            return None
        type_name, body = next(iter(raw.items()))
        mark = raw.key_marks[type_name]
        if type_name == SUBTREE:
            return self._subtree(body, mark, path, problems, stack, seen)
        node_type = self.registry.get(type_name)
        if node_type is None:
            suggestion = self.registry.suggest(type_name)
            hint = f"did you mean {suggestion!r}?" if suggestion else "see `vest nodes`"
            problems.add(mark, f"unknown node type {type_name!r}", hint)
            return None
        children_raw: YValue | None = None
        params_raw: YMap | None = None
        if node_type.children == "many" and isinstance(body, YList):
            children_raw = body
        elif isinstance(body, YMap):
            params_raw = body
        elif not (isinstance(body, YScalar) and body.value is None):
            expected = {
                "many": "a list of children or a mapping with 'children:'",
                "one": "a mapping with 'child:'",
                "none": "a mapping of parameters",
            }
            problems.add(
                body.mark, f"{type_name} takes {expected[node_type.children]}, got {describe(body)}"
            )
            return None
        args, name, children_raw = node_arguments(
            node_type, params_raw, children_raw, mark, problems, self.check_context
        )
        children = self._children(node_type, children_raw, mark, path, problems, stack, seen)
        if args is None or children is None:
            return None
        return NodeDefinition(node_type, name, args, children, mark)

    def _dedented_parameter(self, raw: YValue) -> tuple[Mark, str, str] | None:
        """A node's parameter written one level too far left (beside the node's type,
        not under it): its place, what is wrong, and how to fix it."""
        if not isinstance(raw, YMap) or len(raw) < 2:
            return None
        type_name, *others = list(raw.entries)
        node_type = self.registry.get(type_name)
        if node_type is None:
            return None
        for key in others:
            if node_type.param(key) is not None or key in ("name", "child", "children"):
                return (
                    raw.key_marks[key],
                    f"{key!r} belongs to {type_name} but is not indented under it",
                    f"indent {key}: as far as {type_name}'s other settings",
                )
        return None

    def load_node(
        self, raw: YMap, path: Path, *, name: str, rate_hz: float, priority: int
    ) -> TreeDefinition:
        """A one-node tree from a node written in another file (a button's action), its
        subtrees relative to ``path``; LoadError listing every problem."""
        problems, seen = Problems(), _Seen()
        root = self._node(raw, path, problems, [resolved(path)], seen)
        problems.raise_if_any()
        assert root is not None
        return TreeDefinition(
            name, rate_hz, "", root, path, seen.files, frozenset(), priority=priority
        )

    def _children(
        self,
        node_type: NodeType,
        raw: YValue | None,
        mark: Mark,
        path: Path,
        problems: Problems,
        stack: list[Path],
        seen: _Seen,
    ) -> list[NodeDefinition] | None:
        if node_type.children == "none":
            return []
        if node_type.children == "one":
            if raw is None:
                problems.add(mark, f"{node_type.name} needs 'child:' with one node")
                return None
            if isinstance(raw, YList):
                problems.add(
                    raw.mark,
                    f"{node_type.name} takes one child, got a list of {len(raw)}",
                    "wrap them in a Sequence",
                )
                return None
            child = self._node(raw, path, problems, stack, seen)
            return [child] if child is not None else None
        if raw is None or not isinstance(raw, YList) or len(raw) == 0:
            problems.add(
                raw.mark if raw is not None else mark,
                f"{node_type.name} needs a list of at least one child",
            )
            return None
        children = [self._node(item, path, problems, stack, seen) for item in raw]
        if any(child is None for child in children):
            return None
        return [child for child in children if child is not None]

    def _subtree(
        self,
        body: YValue,
        mark: Mark,
        path: Path,
        problems: Problems,
        stack: list[Path],
        seen: _Seen,
    ) -> NodeDefinition | None:
        if not isinstance(body, YMap) or not isinstance(body.get("file"), YScalar):
            problems.add(body.mark, "Subtree takes {file: path.yaml, params: {...}}")
            return None
        problems.unknown_fields(
            body.key_marks,
            ("file", "params", "name"),
            message="unknown parameter {key!r} for Subtree",
        )
        file_value = body.get("file")
        assert isinstance(file_value, YScalar)
        target = resolved(path.parent / str(file_value.value))
        if target in stack:
            chain = " -> ".join(self.shown(p) for p in [*stack, target])
            problems.add(
                file_value.mark, f"subtree include cycle: {chain}", "a tree cannot include itself"
            )
            return None
        before = len(problems)
        document = self._read(target, problems, seen)
        if document is None:
            if len(problems) > before:
                # the included file's own problem names it; say where it was included from
                problems.add(file_value.mark, f"cannot include {file_value.value!r}")
            return None
        overrides = read_params(body.get("params"), problems)
        params = self._params(document, problems, overrides, "Subtree")
        root = self._root(document, target, params, problems, [*stack, target], seen)
        raw_name = body.get("name")
        if root is not None and isinstance(raw_name, YScalar) and raw_name.value:
            root.name = str(raw_name.value)
        if root is not None:
            root.subtree = str(file_value.value)
            _part_interruptible(document, root, params, problems, self.check_context)
        return root


def _part_interruptible(
    document: YMap,
    root: NodeDefinition,
    params: dict[str, ParamValue],
    problems: Problems,
    ctx: CheckContext,
) -> None:
    """A part's ``interruptible:`` holds for the sentences in it that do not say their own
    (a part nested in it has said its own first); the tree's setting for the rest. A
    part's other settings are its including tree's, and not read here."""
    [setting] = [param for param in SETTINGS if param.name == "interruptible"]
    part = read_setting(document, setting, params, problems, ctx)
    if part is None:
        return
    for node in root.walk():
        if node.type.param("interruptible") is not None and node.args.get("interruptible") is None:
            node.args["interruptible"] = part
