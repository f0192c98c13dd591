"""The commands a robot finished, kept across restarts, so none is carried out twice."""

from __future__ import annotations

import json
import logging
import threading
from pathlib import Path
from typing import Any

from engine.files.problems import LoadError
from engine.files.whole_file import write_whole
from engine.files.yaml_source import read_bytes

log = logging.getLogger("engine.services.cloud_link")
DONE_KEPT = 1000
MAX_DONE_BYTES = 16 * 1024 * 1024
REPORTED = ("SUCCEEDED", "FAILED", "CANCELED")
"""How a command the robot carried out ended: reported (SUCCEEDED, FAILED), or canceled by
the operator while it ran (kept here, never sent: the service knows)."""


class DoneCommands:
    """Finished command ids and their reports, kept in a JSON file across restarts.

    A file that is there but cannot be read as such is set aside as ``FILE.damaged``
    (``.damaged.1``... when one is there already) and ``damaged`` names where it went."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._done: dict[str, dict[str, Any]] = {}
        self.damaged: Path | None = None
        self._lock = threading.Lock()
        if not path.exists() and not path.is_symlink():
            return  # none yet
        try:  # the one safe reader: a FIFO here is refused, never waited on
            raw = read_bytes(
                path, max_bytes=MAX_DONE_BYTES, kind="record of finished commands", too_big_hint=""
            )
            text = raw.decode("utf-8")
        except LoadError as error:
            self._set_aside(f"cannot be read ({error.problems[0].message})")
            return
        except UnicodeDecodeError as error:
            self._set_aside(f"cannot be read ({error})")
            return
        try:
            loaded = json.loads(text)
        except (ValueError, RecursionError) as error:  # not JSON; nested beyond reading
            self._set_aside(f"is not JSON ({error})")
            return
        if not isinstance(loaded, dict) or not all(
            isinstance(report, dict) and report.get("status") in REPORTED
            for report in loaded.values()
        ):  # a report the service would refuse, on every delivery again
            self._set_aside("does not hold finished commands by id")
            return
        self._done = {str(k): v for k, v in loaded.items()}

    def _set_aside(self, why: str) -> None:
        aside = self.path.with_name(self.path.name + ".damaged")
        number = 0
        while aside.exists():
            number += 1
            aside = self.path.with_name(f"{self.path.name}.damaged.{number}")
        try:
            self.path.replace(aside)
            self.damaged = aside
            kept = f"kept aside as {aside}"
        except OSError as error:
            self.damaged = self.path
            kept = f"left where it is ({error}); it will be replaced"
        log.error(
            "the robot's record of finished commands %s %s; %s. A command delivered again "
            "will not be carried out again (it may have been already): it is reported "
            "failed instead",
            self.path,
            why,
            kept,
        )

    def get(self, command_id: str) -> dict[str, Any] | None:
        with self._lock:
            return self._done.get(command_id)

    def add(self, command_id: str, report: dict[str, Any]) -> None:
        with self._lock:
            self._done[command_id] = report
            while len(self._done) > DONE_KEPT:
                self._done.pop(next(iter(self._done)))
            text = json.dumps(self._done)
        try:
            write_whole(self.path, text.encode("utf-8"))
        except OSError as error:
            log.warning("cannot keep finished commands in %s: %s", self.path, error)
