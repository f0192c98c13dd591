"""Whatever a person names as a file, the robot reads at most the size limit of a regular
file: a FIFO, a device or a folder is refused with its place, and nothing ever hangs."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from engine.blackboard.catalogue import default_catalogue
from engine.dialogs.library import load_dialog
from engine.files.problems import LoadError
from engine.files.yaml_source import MAX_FILE_BYTES, read_text
from engine.hardware.config_file import load_robot_config
from engine.loader.substitution import load_profile
from engine.loader.tree_file import TreeLoader
from engine.nodes.registry import default_registry
from engine.scenario.scenario_file import load_scenario

ROOT = Path(__file__).resolve().parents[2]

READERS: dict[str, Callable[[Path], Any]] = {
    "tree": lambda path: TreeLoader(default_registry(plugins=False), default_catalogue()).load(
        path
    ),
    "profile": load_profile,
    "dialog": lambda path: load_dialog(path, default_catalogue()),
    "scenario": load_scenario,
    "robot config": load_robot_config,
}


def refusal(read: Callable[[Path], Any], path: Path) -> str:
    with pytest.raises(LoadError) as caught:
        read(path)
    [problem] = caught.value.problems
    return str(problem)


@pytest.mark.parametrize("kind", sorted(READERS))
def test_a_fifo_named_as_any_file_is_refused_at_once(kind: str, tmp_path: Path) -> None:
    fifo = tmp_path / "hug.yaml"
    os.mkfifo(fifo)  # nobody ever writes to it: reading it would wait for ever
    assert (
        refusal(READERS[kind], fifo)
        == f"{fifo}:1:1: is not a regular file (a FIFO) (name a .yaml file)"
    )


@pytest.mark.parametrize("kind", sorted(READERS))
def test_a_character_device_named_as_any_file_is_refused(kind: str) -> None:
    assert refusal(READERS[kind], Path("/dev/zero")) == (
        "/dev/zero:1:1: is not a regular file (a character device) (name a .yaml file)"
    )


def test_a_link_to_a_fifo_is_refused_like_the_fifo(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "pipe")
    (tmp_path / "tree.yaml").symlink_to(tmp_path / "pipe")
    assert "is not a regular file (a FIFO)" in refusal(READERS["tree"], tmp_path / "tree.yaml")


def test_a_subtree_pointing_at_a_fifo_is_refused_with_its_place(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "part.yaml")
    tree = tmp_path / "tree.yaml"
    tree.write_text("name: t\nrate_hz: 10\nroot:\n  Subtree: {file: part.yaml}\n")
    with pytest.raises(LoadError) as caught:
        READERS["tree"](tree)
    assert [str(problem) for problem in caught.value.problems] == [
        f"{tmp_path}/part.yaml:1:1: is not a regular file (a FIFO) (name a .yaml file)",
        f"{tree}:4:19: cannot include 'part.yaml'",
    ]


def test_a_file_that_grows_past_the_limit_is_never_read_whole(tmp_path: Path) -> None:
    big = tmp_path / "big.yaml"
    big.write_bytes(b"#" * (MAX_FILE_BYTES + 10))
    with pytest.raises(LoadError, match="more than the 1024 KiB"):
        read_text(big)


def test_a_file_whose_size_stat_cannot_tell_is_still_bounded() -> None:
    # /proc files say 0 bytes; what counts is what is read
    assert read_text(Path("/proc/self/status"), max_bytes=1 << 20).startswith("Name:")
    with pytest.raises(LoadError, match="more than the 0 KiB"):
        read_text(Path("/proc/self/status"), max_bytes=10)


def test_vest_validate_on_a_fifo_ends_at_once_with_exit_1(tmp_path: Path) -> None:
    fifo = tmp_path / "hug.yaml"
    os.mkfifo(fifo)
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            "from engine.cli import main; raise SystemExit(main())",
            "validate",
            str(fifo),
        ],
        capture_output=True,
        text=True,
        timeout=60,  # a guard against a hang, not a timing
        cwd=ROOT,
    )
    assert done.returncode == 1
    assert "is not a regular file (a FIFO)" in done.stderr
    assert "Traceback" not in done.stderr
