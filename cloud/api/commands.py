"""People: follow a robot's commands; those whose role may, send and cancel them (each one
written to the audit log)."""

from __future__ import annotations

import json

from fastapi import APIRouter, HTTPException, Request, Response, status

from cloud.api.deps import Commander, CurrentOperator, StoreDep, actor
from cloud.api.robots import granted
from cloud.api.schemas import CommandCreate, CommandPublic
from cloud.roles import Permission, may
from cloud.store.ledger import Command, ConflictError
from engine.remote_commands import command_problem

router = APIRouter(prefix="/robots/{robot}/commands", tags=["operator"])


@router.post("", status_code=status.HTTP_201_CREATED)
def send_command(
    robot: str,
    body: CommandCreate,
    store: StoreDep,
    operator: Commander,
    request: Request,
    response: Response,
) -> CommandPublic:
    """QUEUED and committed before the 201; the same idempotency_key again: 200, the same
    command (409 if it named another). Arguments of built-in types are checked here as the
    robot checks them (422); what only the robot knows (its joints) is checked there."""
    row = granted(store, operator, robot)
    problem = command_problem(body.type, body.args)
    if problem is not None:  # as the robot would find it, but now
        raise HTTPException(
            status.HTTP_422_UNPROCESSABLE_CONTENT, [{"field": "args", "message": problem}]
        )
    try:
        command, created = store.ledger.submit(
            row.id,
            body.type,
            body.args,
            idempotency_key=body.idempotency_key,
            timeout_s=body.timeout_s,
        )
    except ConflictError as error:
        raise HTTPException(status.HTTP_409_CONFLICT, str(error)) from None
    if not created:
        response.status_code = status.HTTP_200_OK
    else:
        store.directory.audit.record(
            actor(operator, request), "send", robot=row.name, detail=_described(command)
        )
    return CommandPublic.of(command, row.name)


@router.get("")
def list_commands(robot: str, store: StoreDep, operator: CurrentOperator) -> list[CommandPublic]:
    """Newest first (the last 50)."""
    row = granted(store, operator, robot)
    sees = may(operator.role, Permission.TELEMETRY)
    return [CommandPublic.of(c, row.name, with_result=sees) for c in store.ledger.recent(row.id)]


@router.get("/{command_id}")
def get_command(
    robot: str, command_id: str, store: StoreDep, operator: CurrentOperator
) -> CommandPublic:
    row = granted(store, operator, robot)
    command = store.ledger.get(row.id, command_id)
    if command is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, f"no command {command_id!r}")
    return CommandPublic.of(command, row.name, with_result=may(operator.role, Permission.TELEMETRY))


@router.post("/{command_id}/cancel")
def cancel_command(
    robot: str, command_id: str, store: StoreDep, operator: Commander, request: Request
) -> CommandPublic:
    """200 with the command, CANCELED (also when it already was); 409 naming how it ended
    when it finished first (a report or a timeout won); 404 for a command not there."""
    row = granted(store, operator, robot)
    try:
        command = store.ledger.cancel(row.id, command_id)
    except ConflictError as error:
        raise HTTPException(status.HTTP_409_CONFLICT, str(error)) from None
    if command is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, f"no command {command_id!r}")
    store.directory.audit.record(
        actor(operator, request), "cancel", robot=row.name, detail=_described(command)
    )
    return CommandPublic.of(command, row.name)


def _described(command: Command) -> str:
    """A command as the audit log tells it: its type, id and arguments (cut to fit)."""
    return f"{command.type} {command.id} {json.dumps(command.args, ensure_ascii=False)}"[:500]
