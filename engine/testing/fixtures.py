"""pytest fixtures for testing trees (installed as the ``vest`` pytest plugin)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from engine.testing.harness import TreeHarness


@pytest.fixture
def tree_harness() -> Callable[..., TreeHarness]:
    """``tree_harness("trees/hug.yaml", profile=None)`` -> a :class:`TreeHarness`."""

    def make(path: str | Path, profile: str | Path | None = None, **options: object) -> TreeHarness:
        return TreeHarness.from_file(path, profile, **options)  # type: ignore[arg-type]

    return make
