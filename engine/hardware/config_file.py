"""Reading a robot config file: parsed with places, then checked whole.

:func:`load_robot_config` is what ``vest run --hardware``, ``vest validate`` and ``vest
devices`` call; the rules live in :mod:`engine.hardware.config_check`, the types in
:mod:`engine.hardware.config`.
"""

from __future__ import annotations

from pathlib import Path

from engine.blackboard.catalogue import KeyCatalogue, default_catalogue
from engine.files.yaml_source import YValue, load_yaml
from engine.hardware.config import RobotConfig
from engine.hardware.config_check import ConfigChecker


def load_robot_config(
    path: Path, shown: str | None = None, *, catalogue: KeyCatalogue | None = None
) -> RobotConfig:
    """Read and check a robot config; :class:`~engine.files.problems.LoadError` lists every
    problem with its file:line:column."""
    name = shown or str(path)
    return check_robot_config(load_yaml(path, name), name, path, catalogue=catalogue)


def check_robot_config(
    document: YValue | None,
    name: str,
    path: Path,
    *,
    catalogue: KeyCatalogue | None = None,
) -> RobotConfig:
    """Check a parsed robot config (see :func:`load_robot_config`)."""
    return ConfigChecker(name, path, catalogue or default_catalogue()).check(document)
