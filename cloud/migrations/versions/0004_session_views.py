"""Each robot's live session as it last pushed it (remote wizard of oz).

Revision ID: 0004
Revises: 0003
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0004"
down_revision = "0003"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "robot_session_view",
        sa.Column("robot_id", sa.Integer(), nullable=False),
        sa.Column("view", sa.JSON(), nullable=False),
        sa.Column("at_s", sa.Float(), nullable=False),
        sa.ForeignKeyConstraint(
            ["robot_id"], ["robots.id"], name="fk_robot_session_view_robot_id_robots"
        ),
        sa.PrimaryKeyConstraint("robot_id", name="pk_robot_session_view"),
    )


def downgrade() -> None:
    op.drop_table("robot_session_view")
