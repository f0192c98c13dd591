"""Generated tree files, profiles and edits of the shipped trees: a clean problem or a
tree that ticks on a virtual clock without an exception and without a servo past its limits."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any

import yaml
from hypothesis import given
from hypothesis import strategies as st

from engine.blackboard.catalogue import default_catalogue
from engine.files.problems import LoadError
from engine.loader.substitution import load_profile
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import default_registry
from engine.testing import TreeHarness
from engine.values.params import Boolean, Choice, Integer, Key, Number, Param

from .hostile_values import SCALARS, VALUES

ROOT = Path(__file__).resolve().parents[2]
REGISTRY = default_registry(plugins=False)
NODE_TYPES = sorted(REGISTRY, key=lambda node_type: node_type.name)
SHIPPED_TREES = sorted((ROOT / "trees").glob("*.yaml"))


KEYS = {
    "state": ["/sensors/touch/any", "/sensors/force/left_n", "/sensors/range/center_mm", "/vars/x"],
    "event": ["/sensors/gesture/last", "/speech/heard", "/iot/inbox"],
}


def sensible(param: Param) -> st.SearchStrategy[Any]:
    """A value a therapist might well write for ``param``."""
    kind = param.type
    if isinstance(kind, Number):
        low = kind.minimum if kind.minimum is not None else -1000.0
        high = kind.maximum if kind.maximum is not None else 1000.0
        return st.floats(low, min(high, low + 100.0), allow_nan=False)
    if isinstance(kind, Integer):
        low = kind.minimum if kind.minimum is not None else 0
        return st.integers(low, low + 12)
    if isinstance(kind, Choice):
        return st.sampled_from(kind.options)
    if isinstance(kind, Boolean):
        return st.booleans()
    if isinstance(kind, Key):
        keys = [key for k in kind.kinds for key in KEYS.get(k, [])] or KEYS["state"]
        if kind.access == "write":
            keys = ["/vars/x", "/vars/y"]
        return st.sampled_from(keys)
    if type(kind).__name__ == "Color":
        return st.sampled_from(["pink", "blue", "#FF0000", "off"])
    if param.name == "joint":
        return st.sampled_from(["neck", "left_arm", "tail"])
    return st.sampled_from(["hello", "It is {temperature_f:.0f}", 3, "default"])


def node(depth: int = 0) -> st.SearchStrategy[Any]:
    """A node mapping built from the declarations: mostly sensible, sometimes absurd."""
    leaves = [t for t in NODE_TYPES if t.children == "none"]
    parents = [t for t in NODE_TYPES if t.children != "none"] if depth < 3 else []

    @st.composite
    def build(draw: st.DrawFn) -> Any:
        node_type = draw(st.sampled_from(leaves + parents))
        args: dict[str, Any] = {}
        for param in node_type.params:
            if param.required or draw(st.booleans()):
                hostile = draw(st.integers(0, 9)) == 0
                args[param.name] = draw(VALUES if hostile else sensible(param))
        if draw(st.integers(0, 19)) == 0:
            args[draw(st.sampled_from(["txt", "name", "child", "children", "volum"]))] = draw(
                SCALARS
            )
        if node_type.children == "many":
            args["children"] = draw(st.lists(node(depth + 1), min_size=1, max_size=3))
        elif node_type.children == "one":
            args["child"] = draw(node(depth + 1))
        typo = draw(st.integers(0, 29)) == 0
        name = draw(st.sampled_from(["Chek", "Sya", ""])) if typo else node_type.name
        return {name: args}

    return build()


TREE_FILES = st.fixed_dictionaries(
    {"root": node()},
    optional={
        "name": st.one_of(st.just("fuzzed"), st.just("fuzzed"), SCALARS),
        "rate_hz": st.one_of(st.just(10), st.just(20), SCALARS),
        "params": st.dictionaries(st.sampled_from(["p", "q"]), SCALARS, max_size=2),
        "description": SCALARS,
    },
)


def dumped(document: Any) -> str | None:
    try:
        return yaml.safe_dump(document, allow_unicode=True, sort_keys=False)
    except (yaml.YAMLError, UnicodeEncodeError):
        return None  # not writable as YAML at all (a person could not have written it)


def load_and_tick(path: Path) -> None:
    """Load the tree; if it loads, tick it for two virtual seconds with the world busy."""
    try:
        robot = TreeHarness.from_file(path, registry=REGISTRY)
    except LoadError as error:
        assert error.problems, "a LoadError names at least one problem"
        for problem in error.problems:
            assert problem.mark.line >= 1 and problem.mark.column >= 1
        return
    robot.set("/sensors/touch/any", True)
    robot.set("/sensors/force/left_n", 6.0)
    robot.set("/sensors/force/right_n", 6.0)
    robot.advance(2.0)
    for move in robot.did("servo"):
        assert math.isfinite(move["angle_deg"]) and -180.0 <= move["angle_deg"] <= 180.0


@given(TREE_FILES)
def test_a_generated_tree_is_a_clean_problem_or_a_clean_run(document: dict[str, Any]) -> None:
    text = dumped(document)
    if text is None:
        return
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "tree.yaml"
        path.write_text(text, encoding="utf-8")
        load_and_tick(path)


@st.composite
def edited(draw: st.DrawFn) -> str:
    """A shipped tree with a few characters deleted, repeated or swapped."""
    text = draw(st.sampled_from(SHIPPED_TREES)).read_text()
    for _ in range(draw(st.integers(1, 4))):
        if not text:
            break
        at = draw(st.integers(0, len(text) - 1))
        edit = draw(st.sampled_from(["delete", "repeat", "swap", "insert"]))
        if edit == "delete":
            text = text[:at] + text[at + 1 :]
        elif edit == "repeat":
            text = text[:at] + text[at] * draw(st.integers(2, 5)) + text[at + 1 :]
        elif edit == "swap" and at + 1 < len(text):
            text = text[:at] + text[at + 1] + text[at] + text[at + 2 :]
        else:
            text = (
                text[:at]
                + draw(st.sampled_from([":", "-", " ", "\t", "'", '"', "{", "&a", "*a", "\\"]))
                + text[at:]
            )
    return text


@given(edited())
def test_a_mistyped_shipped_tree_is_a_clean_problem_or_a_clean_run(text: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "parts").mkdir()
        for part in (ROOT / "trees" / "parts").glob("*.yaml"):
            (Path(folder) / "parts" / part.name).write_text(part.read_text())
        path = Path(folder) / "tree.yaml"
        path.write_text(text, encoding="utf-8")
        load_and_tick(path)


@given(
    st.sampled_from(SHIPPED_TREES),
    st.dictionaries(
        st.sampled_from(
            [
                "volume",
                "hug_threshold_n",
                "hug_rest_s",
                "thanks_rest_s",
                "turn_deg",
                "max_mm",
                "greeting",
                "hug_color",
                "dialog",
                "unknown_one",
            ]
        ),
        SCALARS,
        max_size=3,
    ),
)
def test_a_generated_profile_is_a_clean_problem_or_a_clean_run(
    tree: Path, values: dict[str, Any]
) -> None:
    text = dumped({"profile": "fuzzed", "params": values})
    if text is None:
        return
    with tempfile.TemporaryDirectory() as folder:
        profile_path = Path(folder) / "fuzzed.yaml"
        profile_path.write_text(text, encoding="utf-8")
        try:
            profile = load_profile(profile_path)
            TreeLoader(REGISTRY, default_catalogue(), profile=profile).load(tree)
        except LoadError as error:
            assert error.problems
