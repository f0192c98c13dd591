"""pytest fixtures for testing trees (installed as the ``vest`` pytest plugin)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import py_trees
import pytest

from engine.testing.harness import TreeHarness


@pytest.fixture(autouse=True)
def clean_blackboard() -> Iterator[None]:
    """py_trees' blackboard is process-wide: every test starts and ends with it empty."""
    py_trees.blackboard.Blackboard.clear()
    yield
    py_trees.blackboard.Blackboard.clear()


@pytest.fixture
def tree_harness() -> Callable[..., TreeHarness]:
    """``tree_harness("trees/hug.yaml", profile=None)`` -> a :class:`TreeHarness`."""

    def make(path: str | Path, profile: str | Path | None = None, **options: object) -> TreeHarness:
        return TreeHarness.from_file(path, profile, **options)  # type: ignore[arg-type]

    return make
