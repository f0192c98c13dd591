"""The house's shape, checked: imports run one way, modules stay readable, time comes
from the clock, and no module outside a chip's own names the chip."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENGINE = ROOT / "engine"
MAX_LINES = 420  # "about 400": a module one reads in one sitting


def _modules() -> dict[str, Path]:
    modules = {}
    for path in ENGINE.rglob("*.py"):
        parts = path.relative_to(ENGINE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        modules[name] = path
    return modules


def _imports(path: Path, modules: dict[str, Path]) -> set[str]:
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            candidates = [node.module, *(f"{node.module}.{a.name}" for a in node.names)]
        elif isinstance(node, ast.Import):
            candidates = [a.name for a in node.names]
        else:
            continue
        found.update(c for c in candidates if c in modules)
    return found


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in graph[node]:
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in list(graph):
        if node not in index:
            visit(node)
    return found


def test_no_import_circle_between_engine_modules() -> None:
    modules = _modules()
    graph: dict[str, set[str]] = defaultdict(set)
    for name, path in modules.items():
        graph[name] |= _imports(path, modules) - {name}
    assert _cycles(graph) == []


def _package(module: str) -> str:
    """engine.drivers.bus_manager -> engine.drivers; engine.clock -> engine.clock."""
    return ".".join(module.split(".")[:2])


def test_no_import_circle_between_engine_packages() -> None:
    """Packages form layers too (scripts/package_graph.py prints them): drivers below the
    simulated vest, speech and vision below the robot's assembly of them, even where no
    two modules import each other. An import inside a function counts."""
    modules = _modules()
    graph: dict[str, set[str]] = defaultdict(set)
    why: dict[tuple[str, str], str] = {}
    for name, path in modules.items():
        source = _package(name)
        graph[source]
        for target in _imports(path, modules):
            edge = (source, _package(target))
            if edge[1] not in (source, "engine"):
                graph[source].add(edge[1])
                why.setdefault(edge, f"{path.relative_to(ROOT)} imports {target}")
    circles = [
        " <-> ".join(cycle)
        + "; "
        + "; ".join(why[a, b] for a in cycle for b in cycle if (a, b) in why)
        for cycle in _cycles(graph)
    ]
    assert circles == []


def test_no_engine_module_is_too_long_to_read_in_one_sitting() -> None:
    long = {
        str(path.relative_to(ENGINE.parent)): lines
        for path in ENGINE.rglob("*.py")
        if (lines := len(path.read_text().splitlines())) > MAX_LINES
    }
    assert long == {}


CHIP_NAMES = re.compile(
    r"[\"'](mpr121|ads1115|mcp3008|vl53l0x|zx_gesture|srf02|mcp9808|pca9685|maestro|tca9548a)[\"']"
)


def test_only_a_chip_s_own_module_names_the_chip() -> None:
    naming = {
        str(path.relative_to(ENGINE.parent)): count
        for path in ENGINE.rglob("*.py")
        if "hardware/chips" not in path.as_posix()
        and (count := len(CHIP_NAMES.findall(path.read_text())))
    }
    assert naming == {}


def test_only_the_clock_module_reads_time_or_sleeps() -> None:
    pattern = re.compile(r"\btime\.(time|monotonic|sleep|perf_counter)\(|\bdatetime\.now\(")
    readers = sorted(
        str(path.relative_to(ENGINE.parent))
        for path in ENGINE.rglob("*.py")
        if path.name != "clock.py" and pattern.search(path.read_text())
    )
    assert readers == []


def _docstrings(tree: ast.AST) -> set[int]:
    """ids of the string constants that are docstrings (modules, classes, functions)."""
    found: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                found.add(id(body[0].value))
    return found


def test_every_sensor_key_name_is_written_once_in_the_catalogue() -> None:
    written: list[str] = []
    for path in ENGINE.rglob("*.py"):
        if path.name == "catalogue.py":
            continue
        tree = ast.parse(path.read_text())
        docstrings = _docstrings(tree)
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Constant)
                and isinstance(node.value, str)
                and node.value.startswith("/sensors/")
                and id(node) not in docstrings
            ):
                written.append(f"{path.relative_to(ENGINE.parent)}:{node.lineno}")
    assert written == []


def test_the_cloud_service_loads_no_robot_code() -> None:
    """A cloud host runs the service alone: importing it, or `vest cloud`'s command line,
    loads no behavior trees, no speech, no vision; what both sides share (the commands, the
    clock) imports none."""
    program = (
        "import sys, cloud.app, cloud.server; from engine.cli import build_parser;"
        "build_parser('cloud').parse_args(['cloud', 'add-operator', 'ana']);"
        "robot = ('py_trees', 'engine.nodes', 'engine.speech', 'engine.vision', 'cv2',"
        " 'onnxruntime', 'faster_whisper', 'engine.drivers', 'engine.hardware', 'engine.sim',"
        " 'engine.media', 'engine.robot_io', 'engine.vision_training');"
        "print(sorted(m for m in sys.modules if m.startswith(robot)))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, check=True, cwd=ROOT
    )
    assert loaded.stdout.strip() == "[]"
