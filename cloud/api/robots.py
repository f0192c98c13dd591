"""People: who they are, the robots they see, and each robot's latest telemetry (for the
roles that may see it)."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, HTTPException, status

from cloud.api.deps import CurrentOperator, StoreDep, TelemetryReader
from cloud.api.schemas import AccountPublic, RobotPublic
from cloud.roles import Permission, may
from cloud.services import CloudStore
from cloud.store.tables import RobotRow
from engine.remote_commands import command_catalogue

router = APIRouter(prefix="/robots", tags=["operator"])
ONLINE_WITHIN_S = 15.0
"""A robot waiting in a long-poll, or that called in this recently, is online (a robot
pushes telemetry every second and long-polls again as soon as one ends)."""


def granted(store: StoreDep, operator: CurrentOperator, robot: str) -> RobotRow:
    """The robot, or 404 whether it does not exist or is not this person's to see."""
    row = store.directory.granted_robot(operator, robot)
    if row is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, f"no robot {robot!r}")
    return row


@router.get("")
def list_robots(store: StoreDep, operator: CurrentOperator) -> list[RobotPublic]:
    return [robot_public(store, row) for row in store.directory.robots_of(operator)]


def robot_public(store: CloudStore, row: RobotRow) -> RobotPublic:
    """The robot as its operator sees it: online or not, and when it last called in."""
    last_seen_s = store.telemetry.last_seen(row.id, row.last_seen_s)
    online = store.telemetry.is_polling(row.id) or (
        last_seen_s is not None and store.clock.now() - last_seen_s <= ONLINE_WITHIN_S
    )
    return RobotPublic(name=row.name, online=online, last_seen_s=last_seen_s)


@router.get("/{robot}/command-types")
def command_types(
    robot: str, store: StoreDep, operator: CurrentOperator
) -> dict[str, list[dict[str, Any]]]:
    """The command types the robot carries out, with each one's arguments (for forms)."""
    granted(store, operator, robot)
    return command_catalogue()


@router.get("/{robot}/telemetry")
def robot_telemetry(
    robot: str, store: StoreDep, operator: TelemetryReader
) -> dict[str, dict[str, Any]]:
    return store.telemetry.latest(granted(store, operator, robot).id)


me = APIRouter(tags=["operator"])


@me.get("/me")
def who_am_i(operator: CurrentOperator) -> AccountPublic:
    """The account behind the token: its role, what the role may do, and when the token
    expires (the page shows commands read-only to a role that may not send them)."""
    return AccountPublic(
        name=operator.name,
        role=operator.role or "",
        can_command=may(operator.role, Permission.COMMAND),
        can_press=may(operator.role, Permission.PRESS),
        sees_telemetry=may(operator.role, Permission.TELEMETRY),
        expires_at_s=operator.expires_at_s,
    )
