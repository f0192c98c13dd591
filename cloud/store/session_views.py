"""What each robot's live session looks like, as the robot last pushed it (remote wizard of
oz): its trees in the live view's words, what happened lately and its button board.

One row a robot, written whole on each push (a robot pushes at most twice a second, and only
when something changed), so every worker of every host reads the same view from the
database; a push rings the robot's doorbell (through PostgreSQL's NOTIFY on PostgreSQL) so
the pages' streams send it at once. The robot's consent gate decided what is in it: what a
person's consent keeps from the cloud never arrives here.
"""

from __future__ import annotations

from typing import Any

from cloud.store.database import Database
from cloud.store.notifications import Announcer
from cloud.store.tables import SessionViewRow
from engine.clock import Clock

View = dict[str, Any]


class SessionViews:
    def __init__(self, db: Database, clock: Clock, announcer: Announcer) -> None:
        self.db = db
        self.clock = clock
        self.announcer = announcer

    def put(self, robot_id: int, view: View) -> None:
        """Keep ``view`` as the robot's session now, and tell the pages."""
        now_s = self.clock.now()
        with self.db.transaction() as session:
            row = session.get(SessionViewRow, robot_id)
            if row is None:
                session.add(SessionViewRow(robot_id=robot_id, view=view, at_s=now_s))
            else:
                row.view, row.at_s = view, now_s
            self.announcer.within(session, robot_id)
        self.announcer.after(robot_id)

    def get(self, robot_id: int) -> tuple[View, float] | None:
        """The robot's last view and when it came (seconds since the epoch); None when the
        robot never pushed one."""
        with self.db.transaction() as session:
            row = session.get(SessionViewRow, robot_id)
            return None if row is None else (dict(row.view), row.at_s)
