"""Named dependencies: the store, the caller behind the bearer token, and what its role
lets it do."""

from __future__ import annotations

import datetime as dt
from collections.abc import Awaitable, Callable
from typing import Annotated

from fastapi import Depends, HTTPException, Request, status
from starlette.concurrency import run_in_threadpool

from cloud.roles import Permission, may, roles_that
from cloud.services import CloudStore
from cloud.store.audit import Actor
from cloud.store.directory import Principal


async def get_store(request: Request) -> CloudStore:
    store: CloudStore = request.app.state.store
    return store


StoreDep = Annotated[CloudStore, Depends(get_store)]


def _refused(reason: str) -> HTTPException:
    return HTTPException(
        status.HTTP_401_UNAUTHORIZED, reason, headers={"WWW-Authenticate": "Bearer"}
    )


async def _caller(request: Request, store: StoreDep) -> Principal:
    """The token's owner; a token seen lately is answered from memory, on the event loop
    (dependencies declared ``def`` would each cost a hop to a worker thread). 401 without
    a valid token, saying so when it expired."""
    header = request.headers.get("authorization", "")
    scheme, _, token = header.partition(" ")
    token = token.strip()
    principal = None
    if scheme.lower() == "bearer" and token:
        principal = store.principals.remembered(token) or await run_in_threadpool(
            store.principals.identify, token
        )
    if principal is None:
        raise _refused("a valid bearer token is needed (Authorization: Bearer TOKEN)")
    if principal.expired(store.clock.now()):
        when = dt.datetime.fromtimestamp(principal.expires_at_s or 0.0, dt.UTC)
        raise _refused(
            f"this token expired on {when:%Y-%m-%d %H:%M} UTC; ask an admin for a new one "
            f"(vest cloud rotate {principal.kind} {principal.name})"
        )
    return principal


async def _operator(caller: Annotated[Principal, Depends(_caller)]) -> Principal:
    if caller.kind != "operator":
        raise HTTPException(status.HTTP_404_NOT_FOUND, "not found")
    return caller


async def _robot(caller: Annotated[Principal, Depends(_caller)]) -> Principal:
    if caller.kind != "robot":
        raise HTTPException(status.HTTP_404_NOT_FOUND, "not found")
    return caller


CurrentOperator = Annotated[Principal, Depends(_operator)]
"""A person's account, of any role (checked by the endpoint or by :func:`allowed_to`)."""
CurrentRobot = Annotated[Principal, Depends(_robot)]


def refusal(person: Principal, permission: Permission) -> HTTPException:
    """403 naming the account's role and what it lacks."""
    return HTTPException(
        status.HTTP_403_FORBIDDEN,
        f"{person.name} has the role {person.role!r}, which may not {permission.value}; "
        f"only {', '.join(roles_that(permission))} may (an admin changes a role with "
        "vest cloud set-role NAME ROLE)",
    )


def allowed_to(permission: Permission) -> Callable[[Principal], Awaitable[Principal]]:
    """A dependency: the person, if their role may do ``permission``; else 403."""

    async def check(person: CurrentOperator) -> Principal:
        if not may(person.role, permission):
            raise refusal(person, permission)
        return person

    return check


Commander = Annotated[Principal, Depends(allowed_to(Permission.COMMAND))]
"""A person whose role may send and cancel commands (admin, operator)."""
Presser = Annotated[Principal, Depends(allowed_to(Permission.PRESS))]
"""A person whose role may press a robot's buttons (admin, operator, therapist)."""
TelemetryReader = Annotated[Principal, Depends(allowed_to(Permission.TELEMETRY))]
"""A person whose role may see telemetry (admin, operator, therapist)."""


def actor(person: Principal, request: Request) -> Actor:
    """The person as the audit log names them, with the address the request came from
    (the real client's behind a proxy the service trusts: ``--forwarded-allow-ips``)."""
    client = request.client.host if request.client else "unknown"
    return Actor(person.name, person.role or "", client)
