"""Operators: their robots, and each robot's latest telemetry."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, HTTPException, status

from cloud.api.deps import CurrentOperator, StoreDep
from cloud.api.schemas import RobotPublic
from cloud.store.tables import RobotRow

router = APIRouter(prefix="/robots", tags=["operator"])
ONLINE_WITHIN_S = 60.0
"""A robot that called in this recently is online (it long-polls at least every 30 s)."""


def granted(store: StoreDep, operator: CurrentOperator, robot: str) -> RobotRow:
    """The robot, or 404 whether it does not exist or is not this operator's."""
    row = store.directory.granted_robot(operator.id, robot)
    if row is None:
        raise HTTPException(status.HTTP_404_NOT_FOUND, f"no robot {robot!r}")
    return row


@router.get("")
def list_robots(store: StoreDep, operator: CurrentOperator) -> list[RobotPublic]:
    now = store.clock.now()
    return [
        RobotPublic(
            name=row.name,
            online=row.last_seen_s is not None and now - row.last_seen_s <= ONLINE_WITHIN_S,
            last_seen_s=row.last_seen_s,
        )
        for row in store.directory.robots_of(operator.id)
    ]


@router.get("/{robot}/telemetry")
def robot_telemetry(
    robot: str, store: StoreDep, operator: CurrentOperator
) -> dict[str, dict[str, Any]]:
    return store.telemetry.latest(granted(store, operator, robot).id)
