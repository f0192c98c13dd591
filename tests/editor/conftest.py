"""What the editor's tests share: a project folder of their own (a copy of the shipped
trees and dialogs) and the editor serving it on loopback."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from engine.cli.edit_checks import ValidateChecks
from engine.cli.edit_tries import HearCheck, TryOnSimulatedVest
from engine.cli.run_inputs import DEFAULT_HARDWARE, load_config, robot_catalogue
from engine.editor.palette import palette
from engine.editor.server import EditorServer
from engine.editor.workspace import Workspace
from engine.files.problems import Problems
from engine.nodes.registry import default_registry

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def project(tmp_path: Path) -> Path:
    """A copy of the shipped trees and dialogs: what a therapist's folder holds."""
    folder = tmp_path / "project"
    shutil.copytree(ROOT / "trees", folder / "trees")
    shutil.copytree(ROOT / "dialogs", folder / "dialogs")
    return folder


CONFIG = load_config(ROOT / DEFAULT_HARDWARE, Problems())
"""The simulated vest: its pads, joints and devices (as `vest edit` checks against)."""


@pytest.fixture
def workspace(project: Path) -> Workspace:
    registry = default_registry()
    return Workspace(project, registry, ValidateChecks(project, registry, CONFIG))


@pytest.fixture
def editor(workspace: Workspace) -> Iterator[str]:
    """The editor on ``project``, on loopback: its address."""
    registry = workspace.registry
    offered = palette(registry, CONFIG, robot_catalogue(CONFIG, registry))
    try_out = TryOnSimulatedVest(workspace.folder, ROOT / DEFAULT_HARDWARE, offered["pads"])
    server = EditorServer(
        workspace, offered, port=0, try_out=try_out, hear_check=HearCheck(), watch=try_out.watch
    )
    server.start()
    try:
        yield server.url
    finally:
        server.stop()
        try_out.stop_watching()
