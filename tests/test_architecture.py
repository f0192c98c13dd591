"""The house's shape, checked: imports run one way, modules stay readable, time comes
from the clock, and no module outside a chip's own names the chip."""

from __future__ import annotations

import ast
import importlib.util
import re
import subprocess
import sys
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[1]
ENGINE = ROOT / "engine"
MAX_LINES = 420  # "about 400": a module one reads in one sitting


def _load_package_graph() -> ModuleType:
    """scripts/package_graph.py: the one reading of the engine's imports (modules and
    packages; relative imports and imports inside functions count)."""
    spec = importlib.util.spec_from_file_location(
        "package_graph", ROOT / "scripts/package_graph.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


GRAPH = _load_package_graph()


def test_no_import_circle_between_engine_modules() -> None:
    modules = GRAPH.modules()
    graph = {name: set(GRAPH.imports(path, modules)) - {name} for name, path in modules.items()}
    assert GRAPH.components(graph) == []


def test_no_import_circle_between_engine_packages() -> None:
    """Packages form layers too (scripts/package_graph.py prints them): drivers below the
    simulated vest, speech and vision below the robot's assembly of them, even where no
    two modules import each other. An import inside a function counts."""
    graph, why = GRAPH.package_graph()
    circles = [
        " <-> ".join(cycle)
        + "; "
        + "; ".join(line for a in cycle for b in cycle for line in why.get((a, b), [])[:1])
        for cycle in GRAPH.components(graph)
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
