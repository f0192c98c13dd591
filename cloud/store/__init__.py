"""What the cloud service keeps, in a SQL database (SQLite file by default, PostgreSQL by
URL), through SQLAlchemy 2 with short transactions."""
