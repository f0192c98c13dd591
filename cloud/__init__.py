"""The cloud service operators use to watch and command robots (issue 9, in progress).

``cloud.store`` holds what the service keeps: operators, robots and their tokens, which
operator may see which robot, the command ledger and the latest telemetry.
"""
