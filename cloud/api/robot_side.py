"""Robots: claim their next command (long-poll), report results, push telemetry."""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, HTTPException, Query, Request, Response, status
from sqlalchemy.orm import Session
from starlette.concurrency import run_in_threadpool

from cloud.api.deps import CurrentRobot, StoreDep
from cloud.api.schemas import (
    ClaimedCommand,
    CommandPublic,
    ResultReport,
    SessionViewReport,
    TelemetryReport,
)
from cloud.store.ledger import ConflictError
from cloud.store.telemetry import TelemetryFullError

router = APIRouter(prefix="/robot", tags=["robot"])


@router.get("/commands/next", response_model=None)
async def next_command(
    request: Request,
    store: StoreDep,
    robot: CurrentRobot,
    wait_s: Annotated[float, Query(ge=0, le=60)] = 0.0,
    only: Annotated[Literal["press"] | None, Query()] = None,
) -> ClaimedCommand | Response:
    """The next command, now IN_PROGRESS under a lease of ``lease_s``; 204 when none came within
    ``wait_s`` (at most the service's max_wait_s). ``only=press``: a press of a button alone
    (a robot still carrying out another command takes the therapist's presses meanwhile).

    A command is only taken for a caller still there: a long-poll whose client went away,
    or that the same robot replaced with a newer one, ends without taking anything (else the
    command would wait out its lease before the robot saw it). A robot whose token is revoked
    while it waits is answered 401 before anything is taken (within the token cache's 5 s)."""
    deadline_s = store.clock.now() + min(wait_s, store.settings.max_wait_s)
    token = request.headers.get("authorization", "").partition(" ")[2].strip()
    with store.telemetry.polling(robot.id) as superseded:
        store.doorbell.ring(robot.id)  # an older long-poll of this robot wakes and ends
        while not (superseded() or store.closing.is_set() or await request.is_disconnected()):

            def still_valid(session: Session) -> None:  # only when there is one to take
                if store.principals.authenticate(token, session) is None:
                    raise PermissionError("this robot's token is revoked")

            try:
                command = await run_in_threadpool(
                    store.ledger.claim_next, robot.id, still_valid, only_type=only
                )
            except PermissionError as error:
                raise HTTPException(status.HTTP_401_UNAUTHORIZED, str(error)) from None
            if command is not None:
                public = CommandPublic.of(command, robot.name)
                return ClaimedCommand(**public.model_dump(), lease_s=store.ledger.lease_s)
            left_s = deadline_s - store.clock.now()
            if left_s <= 0:
                break
            await store.doorbell.wait(robot.id, min(left_s, store.settings.recheck_s))
    return Response(status_code=status.HTTP_204_NO_CONTENT)


@router.post("/commands/{command_id}/progress")
def report_progress(command_id: str, store: StoreDep, robot: CurrentRobot) -> CommandPublic:
    """The robot is still carrying the command out: its lease starts again. 200 with the
    command (CANCELED: the operator no longer wants it); 404 for one that is not this
    robot's."""
    try:
        command = store.ledger.extend_lease(robot.id, command_id)
    except ConflictError as error:  # changing too fast to change now: ask again
        raise HTTPException(status.HTTP_409_CONFLICT, str(error)) from None
    if command is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, f"no command {command_id!r}")
    return CommandPublic.of(command, robot.name)


@router.post("/commands/{command_id}/result")
def report_result(
    command_id: str, body: ResultReport, store: StoreDep, robot: CurrentRobot
) -> CommandPublic:
    """200 (also for the same report again); 409 for a different report of a finished
    command; 404 for a command that is not this robot's."""
    try:
        command = store.ledger.report(robot.id, command_id, body.status, body.result)
    except ConflictError as error:
        raise HTTPException(status.HTTP_409_CONFLICT, str(error)) from None
    if command is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, f"no command {command_id!r}")
    return CommandPublic.of(command, robot.name)


@router.post("/telemetry", status_code=status.HTTP_204_NO_CONTENT)
async def push_telemetry(body: TelemetryReport, store: StoreDep, robot: CurrentRobot) -> None:
    """Kept in memory (written in batches). 422 when the robot would hold more keys than
    the service keeps for one robot (its first push of a worker reads its stored keys)."""
    if not store.telemetry.knows(robot.id):  # its stored keys, once a worker: the database
        await run_in_threadpool(store.telemetry.learn, robot.id)
    try:
        store.telemetry.put(robot.id, body.values)
    except TelemetryFullError as error:
        problem = {"field": "values", "message": str(error)}
        raise HTTPException(422, [problem]) from None


@router.post("/session", status_code=status.HTTP_204_NO_CONTENT)
async def push_session(body: SessionViewReport, store: StoreDep, robot: CurrentRobot) -> None:
    """The robot's live session as it stands (kept whole; the pages hear of it at once)."""
    await run_in_threadpool(store.sessions.put, robot.id, body.view.model_dump())
