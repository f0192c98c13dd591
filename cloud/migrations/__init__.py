"""The database's schema history (Alembic); ``Database`` brings any database up to date."""
