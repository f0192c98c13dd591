"""Ringing every worker's doorbell through PostgreSQL's LISTEN/NOTIFY.

With several service processes on one PostgreSQL database, a command queued in one worker
must wake the robot's long-poll in another. The ledger sends a notification within each
transaction that changes a robot's commands (``Announcer``); a listener thread in each
worker rings its local doorbell for each one it receives. A lost
notification (the listener reconnecting, say) costs only time: waiters re-check the ledger.
"""

from __future__ import annotations

import logging
import threading

import psycopg
from sqlalchemy import Engine, text
from sqlalchemy.orm import Session

from cloud.store.doorbell import Doorbell
from engine.clock import Clock

log = logging.getLogger(__name__)
CHANNEL = "vest_robot"
RECONNECT_S = 1.0
POLL_S = 0.5
"""How long the listener waits for a notification before it looks at its stop flag."""


class Announcer:
    """The ledger's ChangeListener: rings this worker's doorbell once a change is committed,
    and (``postgresql``) notifies every worker within the change's transaction."""

    def __init__(self, doorbell: Doorbell, *, postgresql: bool) -> None:
        self.doorbell = doorbell
        self.postgresql = postgresql

    def within(self, session: Session, robot_id: int) -> None:
        if self.postgresql:
            session.execute(
                text("SELECT pg_notify(:channel, :robot)"),
                {"channel": CHANNEL, "robot": str(robot_id)},
            )

    def after(self, robot_id: int) -> None:
        self.doorbell.ring(robot_id)


class PostgresListener:
    """Rings ``doorbell`` for every notification another worker (or this one) sends."""

    def __init__(self, engine: Engine, doorbell: Doorbell, clock: Clock) -> None:
        # as the engine connects: several hosts (?host=db1&host=db2) stay several
        _, self.connect_args = engine.dialect.create_connect_args(engine.url)
        self.connect_args.pop("context", None)
        self.doorbell = doorbell
        self.clock = clock
        self._stop = clock.event()
        self._listening = threading.Event()
        self._thread = threading.Thread(target=self._listen, name="pg-listen", daemon=True)
        self._thread.start()

    def wait_listening(self, timeout_s: float) -> bool:
        """True once the listener has subscribed (tests wait for it before notifying)."""
        return self._listening.wait(timeout_s)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)

    def _listen(self) -> None:
        while not self._stop.is_set():
            try:
                with psycopg.connect(autocommit=True, **self.connect_args) as connection:
                    connection.execute(f"LISTEN {CHANNEL}")
                    self._listening.set()
                    while not self._stop.is_set():
                        for note in connection.notifies(timeout=POLL_S):
                            self.doorbell.ring(int(note.payload))
            except (psycopg.Error, ValueError) as error:
                self._listening.clear()
                log.warning("lost PostgreSQL notifications (%s); reconnecting", error)
                self.clock.wait(self._stop, RECONNECT_S)
