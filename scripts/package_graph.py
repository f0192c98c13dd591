"""Print the engine's package-level import graph and its cycles.

A node is a sub-package of engine/ (engine.drivers) or a top-level module (engine.clock);
there is an edge A -> B when any module of A imports any module of B, wherever the import
stands (inside functions and ``if TYPE_CHECKING:`` too). Prints each package's edges, the
strongly connected components of more than one package, and, when there are none, the
packages in layers (each layer imports only layers before it).

    .venv/bin/python scripts/package_graph.py [--why A B]
"""

from __future__ import annotations

import argparse
import ast
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENGINE = ROOT / "engine"


def modules() -> dict[str, Path]:
    """Every engine module by dotted name."""
    found = {}
    for path in sorted(ENGINE.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def package_of(module: str) -> str:
    """engine.drivers.bus_manager -> engine.drivers; engine.clock -> engine.clock."""
    return ".".join(module.split(".")[:2])


def imports(path: Path, known: dict[str, Path]) -> dict[str, int]:
    """The engine modules ``path`` imports, each with the line of its first import."""
    found: dict[str, int] = {}
    here = ".".join(path.relative_to(ROOT).with_suffix("").parts)
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = here.split(".")[: -node.level]
                base = ".".join([*parent, base] if base else parent)
            candidates = [base, *(f"{base}.{alias.name}" for alias in node.names)]
        elif isinstance(node, ast.Import):
            candidates = [alias.name for alias in node.names]
        else:
            continue
        for candidate in candidates:
            if candidate in known:
                found.setdefault(candidate, node.lineno)
    return found


def package_graph() -> tuple[dict[str, set[str]], dict[tuple[str, str], list[str]]]:
    """The package graph, and for each edge the imports that make it (``file:line -> mod``)."""
    known = modules()
    graph: dict[str, set[str]] = defaultdict(set)
    why: dict[tuple[str, str], list[str]] = defaultdict(list)
    for name, path in known.items():
        source = package_of(name)
        graph[source]
        for target_module, line in imports(path, known).items():
            target = package_of(target_module)
            if target != source and target != "engine":
                graph[source].add(target)
                why[source, target].append(f"{path.relative_to(ROOT)}:{line} -> {target_module}")
    return dict(graph), dict(why)


def components(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one node (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, targets = work[-1]
            for target in targets:
                if target not in index:
                    index[target] = low[target] = len(index)
                    stack.append(target)
                    on_stack.add(target)
                    work.append((target, iter(sorted(graph.get(target, ())))))
                    break
                if target in on_stack:
                    low[node] = min(low[node], index[target])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
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
    return found


def layers(graph: dict[str, set[str]]) -> list[list[str]]:
    """Packages by layer: layer n imports only layers below n (the graph has no cycle)."""
    level: dict[str, int] = {}

    def depth(node: str) -> int:
        if node not in level:
            level[node] = 1 + max((depth(t) for t in graph.get(node, ())), default=-1)
        return level[node]

    for node in graph:
        depth(node)
    result: list[list[str]] = [[] for _ in range(max(level.values(), default=-1) + 1)]
    for node, n in level.items():
        result[n].append(node)
    return [sorted(layer) for layer in result]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--why", nargs=2, metavar=("A", "B"), help="imports behind A -> B")
    args = parser.parse_args()
    graph, why = package_graph()
    if args.why:
        source, target = (p if p.startswith("engine") else f"engine.{p}" for p in args.why)
        print("\n".join(why.get((source, target), ["(no such edge)"])))
        return 0
    for package in sorted(graph):
        print(f"{package} -> {', '.join(sorted(graph[package])) or '(nothing)'}")
    cycles = components(graph)
    print()
    if cycles:
        for cycle in cycles:
            print("cycle: " + " <-> ".join(cycle))
        return 1
    print("no cycle; layers, lowest first:")
    for n, layer in enumerate(layers(graph)):
        print(f"  {n}: {' '.join(p.removeprefix('engine.') for p in layer)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
