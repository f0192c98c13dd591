"""What each role of a person's account may do with the robots it sees.

Robots have no role: a robot's token reaches only its own endpoints. A person's account has
one role; the service checks it on every endpoint (403 naming the role and what it lacks).

| role | robots | commands | telemetry | live session | buttons |
|---|---|---|---|---|---|
| admin | every robot | sees, sends, cancels | sees | sees | presses |
| operator | those granted to it | sees, sends, cancels | sees | sees | presses |
| therapist | those granted to it | sees | sees | sees | presses |
| viewer | those granted to it | sees (not their results) | never (a child's data) | sees | never |
"""

from __future__ import annotations

import difflib
from enum import StrEnum

from engine.errors import ConfigError


class Role(StrEnum):
    ADMIN = "admin"
    OPERATOR = "operator"
    THERAPIST = "therapist"
    VIEWER = "viewer"


class Permission(StrEnum):
    """What a role may do; the value says it in words, for a 403."""

    EVERY_ROBOT = "see every robot"
    COMMAND = "send or cancel commands"
    TELEMETRY = "see telemetry (sensor values are a child's data)"
    PRESS = "press the robot's buttons"


ALLOWED: dict[Role, frozenset[Permission]] = {
    Role.ADMIN: frozenset(Permission),
    Role.OPERATOR: frozenset({Permission.COMMAND, Permission.TELEMETRY, Permission.PRESS}),
    Role.THERAPIST: frozenset({Permission.TELEMETRY, Permission.PRESS}),
    Role.VIEWER: frozenset(),
}
DEFAULT_ROLE = Role.OPERATOR


def may(role: str | None, permission: Permission) -> bool:
    """Whether an account of ``role`` may do ``permission`` (an unknown role: nothing)."""
    return role in ALLOWED and permission in ALLOWED[Role(role)]


def roles_that(permission: Permission) -> list[str]:
    """The roles that may do ``permission``, by name."""
    return [role.value for role, allowed in ALLOWED.items() if permission in allowed]


def role_named(name: str) -> Role:
    """The role called ``name``; a ConfigError naming the roles there are."""
    try:
        return Role(name)
    except ValueError:
        close = difflib.get_close_matches(name, [r.value for r in Role], n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ConfigError(
            f"no role {name!r}{hint}; use one of {', '.join(r.value for r in Role)}"
        ) from None
