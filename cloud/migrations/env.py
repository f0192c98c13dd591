"""Alembic's entry: runs the migrations on the connection ``Database`` hands over."""

from __future__ import annotations

from alembic import context

from cloud.store.tables import Table

connection = context.config.attributes["connection"]
context.configure(
    connection=connection,
    target_metadata=Table.metadata,
    render_as_batch=connection.dialect.name == "sqlite",  # SQLite alters tables by copying
)
with context.begin_transaction():
    context.run_migrations()
