"""Named dependencies: the store, and the caller behind the bearer token."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, HTTPException, Request, status
from starlette.concurrency import run_in_threadpool

from cloud.services import CloudStore
from cloud.store.directory import Principal


async def get_store(request: Request) -> CloudStore:
    store: CloudStore = request.app.state.store
    return store


StoreDep = Annotated[CloudStore, Depends(get_store)]


async def _caller(request: Request, store: StoreDep) -> Principal:
    """The token's owner; a token seen lately is answered from memory, on the event loop
    (dependencies declared ``def`` would each cost a hop to a worker thread)."""
    header = request.headers.get("authorization", "")
    scheme, _, token = header.partition(" ")
    token = token.strip()
    principal = None
    if scheme.lower() == "bearer" and token:
        principal = store.principals.remembered(token) or await run_in_threadpool(
            store.principals.authenticate, token
        )
    if principal is None:
        raise HTTPException(
            status.HTTP_401_UNAUTHORIZED,
            "a valid bearer token is needed (Authorization: Bearer TOKEN)",
            headers={"WWW-Authenticate": "Bearer"},
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
CurrentRobot = Annotated[Principal, Depends(_robot)]
