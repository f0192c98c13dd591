"""Session recordings: everything a run did, kept in one SQLite file, replayed later."""
