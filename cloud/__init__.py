"""The cloud service operators use to watch and command robots.

``cloud.app`` builds the service (FastAPI), ``cloud.server`` runs it, ``cloud.store`` holds
what it keeps: operators, robots and their tokens, which operator may see which robot, the
command ledger and the latest telemetry. Importing this package alone loads nothing: the
command line reads :data:`DEFAULT_DB` from here on a robot without the service installed.
"""

DEFAULT_DB = "sqlite:///vest-cloud.db"
