"""The latest telemetry of each robot: one value per key, with when it was sent."""

from __future__ import annotations

from typing import Any

from sqlalchemy import select

from cloud.store.database import Database
from cloud.store.tables import RobotRow, TelemetryRow
from engine.clock import Clock


class Telemetry:
    def __init__(self, db: Database, clock: Clock) -> None:
        self.db = db
        self.clock = clock

    def put(self, robot_id: int, values: dict[str, Any]) -> None:
        """Keep ``values`` as the robot's latest, stamped now; the robot was seen now."""
        now = self.clock.now()
        with self.db.transaction() as session:
            for key, value in values.items():
                row = session.get(TelemetryRow, (robot_id, key))
                if row is None:
                    session.add(TelemetryRow(robot_id=robot_id, key=key, value=value, at_s=now))
                else:
                    row.value, row.at_s = value, now
            robot = session.get(RobotRow, robot_id)
            if robot is not None:
                robot.last_seen_s = now

    def seen(self, robot_id: int) -> None:
        """The robot called in now (a long-poll counts)."""
        with self.db.transaction() as session:
            robot = session.get(RobotRow, robot_id)
            if robot is not None:
                robot.last_seen_s = self.clock.now()

    def latest(self, robot_id: int) -> dict[str, dict[str, Any]]:
        """key -> {"value", "at_s"}."""
        with self.db.transaction() as session:
            rows = session.scalars(
                select(TelemetryRow)
                .where(TelemetryRow.robot_id == robot_id)
                .order_by(TelemetryRow.key)
            )
            return {row.key: {"value": row.value, "at_s": row.at_s} for row in rows}
