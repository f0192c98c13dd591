"""Remembering who a token belongs to for a few seconds.

Every request carries a token, and looking it up costs the database one or two queries:
more than the rest of a telemetry post. A token found valid is trusted for ``ttl_s``; a
token revoked or rotated (by `vest cloud revoke`/`rotate`, in another process), or given
another role, is taken up within that time; an expiry is checked on every request.
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
        """The token's owner (expired or not) if it was found within ``ttl_s``; None means
        "ask ``identify``" (no database is touched here: safe on the event loop)."""
        with self._lock:  # TTLCache is not thread-safe on its own
            return self._known.get(digest(token))

    def authenticate(self, token: str, session: Session | None = None) -> Principal | None:
        """The operator or robot whose token this is, or None (unknown, revoked or expired
        now, by the clock); looked up on ``session`` when one is given (see
        `Directory.authenticate`)."""
        principal = self.identify(token, session)
        return None if principal is None or principal.expired(self.clock.now()) else principal

    def identify(self, token: str, session: Session | None = None) -> Principal | None:
        """The token's owner, expired or not (the caller says which it is); None: unknown
        or revoked."""
        remembered = self.remembered(token)
        if remembered is not None:
            return remembered
        key = digest(token)
        principal = self.directory.holder(token, session)
        with self._lock:
            if principal is None:
                self._known.pop(key, None)
            else:
                self._known[key] = principal
        return principal
