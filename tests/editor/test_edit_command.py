"""`vest edit`: prints where the editor is, serves the folder, and says what is wrong with
its command line in one line."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import urllib.error
import urllib.request
from collections.abc import Callable
from pathlib import Path

import pytest

from engine.cli import main

pytestmark = pytest.mark.realtime

ROOT = Path(__file__).resolve().parents[2]
VEST = "import sys; from engine.cli import main; sys.exit(main())"


def test_vest_edit_prints_its_address_and_serves_the_folder(
    project: Path, at: Callable[[str, str], str]
) -> None:
    process = subprocess.Popen(
        [sys.executable, "-c", VEST, "edit", str(project), "--port", "0"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        assert process.stdout is not None
        line = process.stdout.readline()
        assert line.startswith("editor: http://127.0.0.1:"), line
        address = line.split()[1]
        assert "?token=" in address  # on loopback too
        with urllib.request.urlopen(at(address, "/api/files"), timeout=10) as answer:
            files = json.load(answer)
        assert {"file": "trees/hug.yaml", "kind": "tree"} in files
        with pytest.raises(urllib.error.HTTPError, match="403"):
            urllib.request.urlopen(address.split("?")[0] + "api/files", timeout=10)
    finally:
        process.send_signal(signal.SIGTERM)
        process.wait(timeout=30)


def test_a_folder_that_is_not_there_is_said_in_one_line(tmp_path: Path, capsys) -> None:
    assert main(["edit", str(tmp_path / "nowhere")]) == 2
    err = capsys.readouterr().err
    assert "nowhere: no such folder" in err and "Traceback" not in err


def test_a_port_that_is_not_a_number_is_refused(capsys) -> None:
    with pytest.raises(SystemExit) as ended:  # argparse's own exit, as every command's
        main(["edit", "--port", "http"])
    assert ended.value.code == 2
    assert "must be a port number" in capsys.readouterr().err
