"""Telemetry kept as one row per robot (all its keys in one JSON value) instead of one row
per key: a batch of 200 robots' pushes writes 200 rows, not 6,000.

Revision ID: 0002
Revises: 0001
"""

from __future__ import annotations

from typing import Any

import sqlalchemy as sa
from alembic import op

revision = "0002"
down_revision = "0001"
branch_labels = None
depends_on = None

old = sa.table(
    "telemetry",
    sa.column("robot_id", sa.Integer()),
    sa.column("key", sa.String()),
    sa.column("value", sa.JSON()),
    sa.column("at_s", sa.Float()),
)

per_robot = sa.table(
    "robot_telemetry", sa.column("robot_id", sa.Integer()), sa.column("readings", sa.JSON())
)


def upgrade() -> None:
    new = op.create_table(
        "robot_telemetry",
        sa.Column("robot_id", sa.Integer(), nullable=False),
        sa.Column("readings", sa.JSON(), nullable=False),
        sa.Column("at_s", sa.Float(), nullable=False),
        sa.ForeignKeyConstraint(
            ["robot_id"], ["robots.id"], name="fk_robot_telemetry_robot_id_robots"
        ),
        sa.PrimaryKeyConstraint("robot_id", name="pk_robot_telemetry"),
    )
    robots: dict[int, dict[str, Any]] = {}
    for robot_id, key, value, at_s in op.get_bind().execute(sa.select(old)):
        robots.setdefault(robot_id, {})[key] = {"value": value, "at_s": at_s}
    if robots:
        op.bulk_insert(
            new,
            [
                {
                    "robot_id": robot_id,
                    "readings": readings,
                    "at_s": max(r["at_s"] for r in readings.values()),
                }
                for robot_id, readings in robots.items()
            ],
        )
    op.drop_table("telemetry")


def downgrade() -> None:
    op.create_table(
        "telemetry",
        sa.Column("robot_id", sa.Integer(), nullable=False),
        sa.Column("key", sa.String(200), nullable=False),
        sa.Column("value", sa.JSON(), nullable=True),
        sa.Column("at_s", sa.Float(), nullable=False),
        sa.ForeignKeyConstraint(["robot_id"], ["robots.id"], name="fk_telemetry_robot_id_robots"),
        sa.PrimaryKeyConstraint("robot_id", "key", name="pk_telemetry"),
    )
    rows = op.get_bind().execute(sa.select(per_robot))
    values = [
        {"robot_id": robot_id, "key": key, "value": r["value"], "at_s": r["at_s"]}
        for robot_id, readings in rows
        for key, r in readings.items()
    ]
    if values:
        op.bulk_insert(old, values)
    op.drop_table("robot_telemetry")
