"""Remote wizard of oz: a robot's live session and its buttons, from another room.

``GET /robots/{robot}/session`` is the robot's session as it last pushed it (its trees and
what they do, what happened lately, its button board; every role that sees the robot sees
it, a viewer without what happened: it can quote the child).

``POST /robots/{robot}/press`` ``{"button": N}`` presses one of its buttons (the roles that
may press: admin, operator, therapist): a command of type ``press`` that the robot carries
out exactly as a press on its own buttons page, credited to the account. A press that the
robot has not taken and confirmed within :data:`PRESS_WITHIN_S` is never carried out: it
ends TIMED_OUT, and the page says it was dropped.
"""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, HTTPException, Request, status
from starlette.concurrency import run_in_threadpool

from cloud.api.deps import CurrentOperator, Presser, StoreDep, actor
from cloud.api.robots import granted
from cloud.api.schemas import CommandPublic, PressCreate
from cloud.roles import Permission, may

router = APIRouter(prefix="/robots/{robot}", tags=["operator"])
PRESS_WITHIN_S = 2.0
"""A press the robot has not taken by then is dropped: a late press is a wrong press."""
PRESS = "press"


@router.get("/session")
async def robot_session(robot: str, store: StoreDep, operator: CurrentOperator) -> dict[str, Any]:
    """``{"view": ..., "at_s": ...}``; 404 while the robot has pushed none."""
    row = granted(store, operator, robot)
    stored = await run_in_threadpool(store.sessions.get, row.id)
    if stored is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, f"{robot!r} has sent no session yet")
    view, at_s = stored
    return {"view": shown_to(operator.role, view), "at_s": at_s}


def shown_to(role: str | None, view: dict[str, Any]) -> dict[str, Any]:
    """The view as ``role`` may see it: "what happened" can quote the child (what they
    said, their readings), so a role that may not see telemetry (a viewer) sees the
    buttons and the behaviors without it."""
    if may(role, Permission.TELEMETRY):
        return view
    return {**view, "happened": [], "happened_hidden": True}


@router.post("/press", status_code=status.HTTP_202_ACCEPTED)
def press_button(
    robot: str, body: PressCreate, store: StoreDep, person: Presser, request: Request
) -> CommandPublic:
    """Queued for the robot; its state says what became of it (SUCCEEDED: pressed;
    FAILED: the robot has no such button or no board; TIMED_OUT: dropped, not reached in
    time)."""
    row = granted(store, person, robot)
    command, _ = store.ledger.submit(
        row.id, PRESS, {"button": body.button, "by": person.name}, timeout_s=PRESS_WITHIN_S
    )
    label = _label(store.sessions.get(row.id), body.button)
    store.directory.audit.record(
        actor(person, request), "press", robot=row.name, detail=f"button {body.button}{label}"
    )
    return CommandPublic.of(command, row.name)


def _label(stored: tuple[dict[str, Any], float] | None, number: int) -> str:
    """`` 'Hello'``: the button's label on the board the robot last showed ("" unknown)."""
    board = stored[0].get("board") if stored is not None else None
    buttons = board.get("buttons") if isinstance(board, dict) else None
    for button in buttons if isinstance(buttons, list) else []:
        if isinstance(button, dict) and button.get("id") == number:
            return f" {str(button.get('label'))[:80]!r}"
    return ""
