"""The service's settings, checked when it starts.

Given on the command line (``vest cloud serve --db ... --lease-s ...``) or, for a service
run by a process manager or in a container, from the environment: ``VEST_CLOUD_DB_URL``,
``VEST_CLOUD_LEASE_S`` and so on (pydantic-settings reads them; a value given in code wins
over the environment). Worker processes receive their settings through the same variables.
"""

from __future__ import annotations

import difflib
import os
from typing import Any

from pydantic import Field, ValidationError
from pydantic_settings import BaseSettings, SettingsConfigDict

from cloud import DEFAULT_DB
from engine.errors import ConfigError

DAY_S = 86400.0
ENV_PREFIX = "VEST_CLOUD_"


def _seconds(default: float) -> Any:
    """A time above 0 and at most a day."""
    return Field(default, gt=0, le=DAY_S, allow_inf_nan=False)


class Settings(BaseSettings):
    """``db_url``: SQLite file or PostgreSQL URL; ``lease_s``: how long a robot has to
    report a claimed command; ``default_timeout_s``: how long a command waits to be taken
    unless its operator says; ``max_wait_s``: the longest long-poll; ``recheck_s``: how
    often a long-poll looks at the ledger again; ``max_body_bytes``: larger bodies get 413;
    ``flush_s``: how often telemetry held in memory is written; ``token_cache_s``: how long
    a token found valid is trusted before it is looked up again (a revoked token stops
    working within it). Times in seconds; a value out of range is a ConfigError naming it."""

    model_config = SettingsConfigDict(env_prefix=ENV_PREFIX, frozen=True, extra="forbid")

    db_url: str = DEFAULT_DB
    lease_s: float = _seconds(30.0)
    default_timeout_s: float = _seconds(300.0)
    max_wait_s: float = _seconds(30.0)
    recheck_s: float = _seconds(5.0)
    max_body_bytes: int = Field(64 * 1024, ge=1024, le=16 * 1024 * 1024)
    flush_s: float = _seconds(1.0)
    token_cache_s: float = Field(5.0, ge=0, le=60, allow_inf_nan=False)

    def __init__(self, **values: Any) -> None:
        known = {ENV_PREFIX + name.upper() for name in type(self).model_fields}
        for variable in sorted(os.environ):
            if variable.startswith(ENV_PREFIX) and variable not in known:
                close = difflib.get_close_matches(variable, known, n=1)
                hint = f" (did you mean {close[0]}?)" if close else ""
                raise ConfigError(f"{variable}: no such setting{hint}")
        try:
            super().__init__(**values)
        except ValidationError as error:
            raise ConfigError("; ".join(_problem(item) for item in error.errors())) from None

    def environment(self) -> dict[str, str]:
        """These settings as the environment variables that give them (for workers)."""
        return {ENV_PREFIX + name.upper(): str(value) for name, value in self.model_dump().items()}


FLAGS = {"db_url": "--db", "lease_s": "--lease-s", "default_timeout_s": "--timeout-s"}
"""The settings ``vest cloud serve`` also takes on its command line."""


def _problem(item: Any) -> str:
    """One setting's problem in a line: where it is given, what it must be, what it was."""
    name = ".".join(str(part) for part in item["loc"]) or "settings"
    given = " or ".join(filter(None, (FLAGS.get(name), ENV_PREFIX + name.upper())))
    return f"{name} ({given}): {item['msg'][0].lower()}{item['msg'][1:]} (got {item['input']!r})"
