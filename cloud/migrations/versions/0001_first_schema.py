"""The first schema: operators, robots, grants, commands, telemetry.

Revision ID: 0001
Revises:
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0001"
down_revision = None
branch_labels = None
depends_on = None


def upgrade() -> None:
    for table in ("operators", "robots"):
        extra = [sa.Column("last_seen_s", sa.Float(), nullable=True)] if table == "robots" else []
        op.create_table(
            table,
            sa.Column("id", sa.Integer(), nullable=False),
            sa.Column("name", sa.String(64), nullable=False),
            sa.Column("token_digest", sa.String(64), nullable=False),
            sa.Column("revoked", sa.Boolean(), nullable=False),
            *extra,
            sa.PrimaryKeyConstraint("id", name=f"pk_{table}"),
            sa.UniqueConstraint("name", name=f"uq_{table}_name"),
            sa.UniqueConstraint("token_digest", name=f"uq_{table}_token_digest"),
        )
    op.create_table(
        "grants",
        sa.Column("operator_id", sa.Integer(), nullable=False),
        sa.Column("robot_id", sa.Integer(), nullable=False),
        sa.ForeignKeyConstraint(
            ["operator_id"], ["operators.id"], name="fk_grants_operator_id_operators"
        ),
        sa.ForeignKeyConstraint(["robot_id"], ["robots.id"], name="fk_grants_robot_id_robots"),
        sa.PrimaryKeyConstraint("operator_id", "robot_id", name="pk_grants"),
    )
    op.create_table(
        "commands",
        sa.Column("id", sa.String(36), nullable=False),
        sa.Column("robot_id", sa.Integer(), nullable=False),
        sa.Column("type", sa.String(64), nullable=False),
        sa.Column("args", sa.JSON(), nullable=False),
        sa.Column("state", sa.String(16), nullable=False),
        sa.Column("version", sa.Integer(), nullable=False),
        sa.Column("result", sa.JSON(), nullable=True),
        sa.Column("idempotency_key", sa.String(128), nullable=True),
        sa.Column("created_s", sa.Float(), nullable=False),
        sa.Column("updated_s", sa.Float(), nullable=False),
        sa.Column("timeout_at_s", sa.Float(), nullable=False),
        sa.Column("lease_until_s", sa.Float(), nullable=True),
        sa.Column("deliveries", sa.Integer(), nullable=False),
        sa.ForeignKeyConstraint(["robot_id"], ["robots.id"], name="fk_commands_robot_id_robots"),
        sa.PrimaryKeyConstraint("id", name="pk_commands"),
        sa.UniqueConstraint(
            "robot_id", "idempotency_key", name="uq_commands_robot_id_idempotency_key"
        ),
    )
    op.create_index("ix_commands_state", "commands", ["state"])
    op.create_index("ix_commands_claim", "commands", ["robot_id", "state", "created_s"])
    op.create_table(
        "telemetry",
        sa.Column("robot_id", sa.Integer(), nullable=False),
        sa.Column("key", sa.String(200), nullable=False),
        sa.Column("value", sa.JSON(), nullable=True),
        sa.Column("at_s", sa.Float(), nullable=False),
        sa.ForeignKeyConstraint(["robot_id"], ["robots.id"], name="fk_telemetry_robot_id_robots"),
        sa.PrimaryKeyConstraint("robot_id", "key", name="pk_telemetry"),
    )


def downgrade() -> None:
    op.drop_table("telemetry")
    op.drop_index("ix_commands_claim", "commands")
    op.drop_index("ix_commands_state", "commands")
    op.drop_table("commands")
    op.drop_table("grants")
    op.drop_table("robots")
    op.drop_table("operators")
