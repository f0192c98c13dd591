"""The service's settings, checked when it starts."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass

from engine.errors import ConfigError

DEFAULT_DB = "sqlite:///vest-cloud.db"


@dataclass(frozen=True)
class Settings:
    """``db_url``: SQLite file or PostgreSQL URL; ``lease_s``: how long a robot has to
    report a claimed command; ``max_wait_s``: the longest long-poll; ``recheck_s``: how
    often a long-poll looks at the ledger again; ``max_body_bytes``: larger bodies get 413;
    ``flush_s``: how often telemetry held in memory is written; ``threads``: requests
    worked on at once (each waiting long-poll holds one); ``token_cache_s``: how long a
    token found valid is trusted before it is looked up again (a revoked token stops
    working within it). Times in seconds."""

    db_url: str = DEFAULT_DB
    lease_s: float = 30.0
    default_timeout_s: float = 300.0
    max_wait_s: float = 30.0
    recheck_s: float = 5.0
    max_body_bytes: int = 64 * 1024
    flush_s: float = 1.0
    threads: int = 1000
    token_cache_s: float = 5.0

    def __post_init__(self) -> None:
        for name in ("lease_s", "default_timeout_s", "max_wait_s", "recheck_s", "flush_s"):
            value = getattr(self, name)
            if not 0 < value <= 86400:
                raise ConfigError(
                    f"{name} must be above 0 and at most a day (86400 s), got {value}"
                )
        if not 1024 <= self.max_body_bytes <= 16 * 1024 * 1024:
            raise ConfigError(
                f"setting max_body_bytes must be 1 KiB..16 MiB, got {self.max_body_bytes}"
            )
        if not 0 <= self.token_cache_s <= 60:
            raise ConfigError(f"token_cache_s must be 0..60 s, got {self.token_cache_s}")
        if not 4 <= self.threads <= 10000:
            raise ConfigError(f"setting threads must be 4..10000, got {self.threads}")

    def to_json(self) -> str:
        """For handing to worker processes (``from_json`` reads it back, checked again)."""
        return json.dumps(asdict(self))

    @classmethod
    def from_json(cls, text: str) -> Settings:
        return cls(**json.loads(text))
