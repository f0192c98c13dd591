"""Who runs a command, as the audit trails (the site's and the cloud's) name them."""

from __future__ import annotations

import os
import pwd


def acting_user() -> str:
    """The operating system's account the process runs as, by its user id (``therapy
    (uid 1001)``; ``uid 1001`` when it has no name), never an environment variable such
    as LOGNAME or USER, which anyone may set."""
    uid = os.geteuid()
    try:
        return f"{pwd.getpwuid(uid).pw_name} (uid {uid})"
    except KeyError:  # no name for this user id (a bare container)
        return f"uid {uid}"
