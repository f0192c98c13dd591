"""The test suite in tiers (tests/conftest.py): a plain ``pytest`` runs the fast tier,
never a browser, a database, the real models, a benchmark; naming a path runs it all."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.realtime  # each story starts a pytest of its own

ROOT = Path(__file__).resolve().parents[1]


def collected(*args: str) -> tuple[list[str], str]:
    """The test ids ``pytest ARGS`` would run, and its header and summary."""
    ran = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert ran.returncode == 0, ran.stdout + ran.stderr
    ids = [line for line in ran.stdout.splitlines() if "::" in line]
    return ids, ran.stdout


def test_a_plain_pytest_leaves_out_the_slow_tiers_and_says_so() -> None:
    ids, said = collected()
    assert any(i.startswith("tests/nodes/") for i in ids)  # the fast tier is there
    assert not any("[postgresql]" in i for i in ids)  # no database
    assert not any(i.startswith("tests/test_benchmarks_still_run.py") for i in ids)
    assert not any(i.startswith("tests/editor/test_editor_page.py::") for i in ids)  # browser
    assert not any(i.startswith("tests/test_timelines_unchanged.py") for i in ids)  # models
    assert "deselected" in said


def test_a_path_named_runs_every_test_in_it_whatever_its_tier() -> None:
    ids, said = collected("tests/cloud/test_ledger.py")
    assert any("[postgresql]" in i for i in ids) and any("[sqlite]" in i for i in ids)
    assert "deselected" not in said


def test_tests_chosen_by_name_run_whatever_their_tier() -> None:
    ids, _ = collected("-k", "test_ledger and postgresql")
    assert ids and all("[postgresql]" in i for i in ids)
