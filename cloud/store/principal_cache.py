"""Remembering who a token belongs to for a few seconds.

Every request carries a token, and looking it up costs the database one or two queries:
more than the rest of a telemetry post. A token found valid is trusted for ``ttl_s``; a
token revoked (by `vest cloud revoke`, in another process) stops working within that time.
Unknown tokens are never remembered, so guessing cannot fill the memory.
"""

from __future__ import annotations

import threading

from cachetools import TTLCache
from sqlalchemy.orm import Session

from cloud.store.directory import Directory, Principal
from cloud.store.tokens import digest
from engine.clock import Clock

TTL_S = 5.0


MAX_REMEMBERED = 100_000
"""Valid tokens remembered at most (the least recently used go first): more than any
service has robots and operators."""


class PrincipalCache:
    """Tokens found valid, kept ``ttl_s`` seconds of ``clock`` in cachetools' TTLCache (the
    library made for it: expiry on an injected timer, a bound on size, LRU eviction)."""

    def __init__(self, directory: Directory, clock: Clock, ttl_s: float = TTL_S) -> None:
        self.directory = directory
        self.clock = clock
        self.ttl_s = ttl_s
        self._known: TTLCache[str, Principal] = TTLCache(MAX_REMEMBERED, ttl_s, timer=clock.now)
        self._lock = threading.Lock()

    def remembered(self, token: str) -> Principal | None:
        """The token's owner if it was found valid within ``ttl_s``; None means "ask
        ``authenticate``" (no database is touched here: safe on the event loop)."""
        with self._lock:  # TTLCache is not thread-safe on its own
            return self._known.get(digest(token))

    def authenticate(self, token: str, session: Session | None = None) -> Principal | None:
        """The operator or robot whose token this is, or None (unknown or revoked); looked
        up on ``session`` when one is given (see `Directory.authenticate`)."""
        remembered = self.remembered(token)
        if remembered is not None:
            return remembered
        key = digest(token)
        principal = self.directory.authenticate(token, session)
        with self._lock:
            if principal is None:
                self._known.pop(key, None)
            else:
                self._known[key] = principal
        return principal
