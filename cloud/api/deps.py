"""Named dependencies: the store, and the caller behind the bearer token."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, HTTPException, Request, status

from cloud.services import CloudStore
from cloud.store.directory import Principal


def get_store(request: Request) -> CloudStore:
    store: CloudStore = request.app.state.store
    return store


StoreDep = Annotated[CloudStore, Depends(get_store)]


def _caller(request: Request, store: StoreDep) -> Principal:
    header = request.headers.get("authorization", "")
    scheme, _, token = header.partition(" ")
    principal = store.principals.authenticate(token.strip()) if scheme.lower() == "bearer" else None
    if principal is None:
        raise HTTPException(
            status.HTTP_401_UNAUTHORIZED,
            "a valid bearer token is needed (Authorization: Bearer TOKEN)",
            headers={"WWW-Authenticate": "Bearer"},
        )
    return principal


def _operator(caller: Annotated[Principal, Depends(_caller)]) -> Principal:
    if caller.kind != "operator":
        raise HTTPException(status.HTTP_404_NOT_FOUND, "not found")
    return caller


def _robot(caller: Annotated[Principal, Depends(_caller)]) -> Principal:
    if caller.kind != "robot":
        raise HTTPException(status.HTTP_404_NOT_FOUND, "not found")
    return caller


CurrentOperator = Annotated[Principal, Depends(_operator)]
CurrentRobot = Annotated[Principal, Depends(_robot)]
