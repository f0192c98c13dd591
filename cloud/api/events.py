"""The operator's live stream: server-sent events with what changed on its robots.

``GET /api/v1/events`` (operator token) answers ``text/event-stream``. Events, each a JSON
``data:`` line:

- ``robots``: every robot granted to the operator (name, online, last_seen_s), first and
  whenever one of them changes;
- ``telemetry``: ``{"robot", "values": {key: {"value", "at_s"}}}`` with the keys whose
  values came in since the last one (all of them first); never to a role that may not see
  telemetry (a viewer);
- ``command``: a command (as ``GET .../commands/{id}`` answers it) whenever its version
  grows; the newest 50 of each robot first;
- ``session``: ``{"robot", "view", "at_s"}``, the robot's live session (its trees, what
  happened, its buttons: cloud/api/presses.py) whenever the robot pushed a new one.

The stream wakes at once when a robot's commands or its session change (the same doorbell
as the long-polls) and looks for new telemetry every ``TELEMETRY_EVERY_S``. A comment line every
``KEEPALIVE_S`` keeps proxies from closing an idle stream. It ends after ``STREAM_S`` (the
page then opens a new one), when the service stops, and when the operator's token is
revoked or expires. A role changed meanwhile is taken up within the token cache time.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from typing import Any

from fastapi import APIRouter, Request
from starlette.concurrency import run_in_threadpool
from starlette.responses import Response

from cloud.api.deps import CurrentOperator, StoreDep
from cloud.api.presses import shown_to
from cloud.api.robots import robot_public
from cloud.api.schemas import CommandPublic
from cloud.roles import Permission, may
from cloud.services import CloudStore
from cloud.store.directory import Principal
from engine.web.sse import KEEPALIVE, KEEPALIVE_S, event_stream, frame

router = APIRouter(tags=["operator"])
TELEMETRY_EVERY_S = 1.0
STREAM_S = 300.0


class OperatorView:
    """What this operator's page was last sent, and what changed since."""

    def __init__(self, store: CloudStore, operator: Principal) -> None:
        self.store = store
        self.operator = operator
        self.robot_ids: list[int] = []
        self._robots: list[dict[str, Any]] | None = None
        self._versions: dict[str, int] = {}
        self._telemetry: dict[tuple[int, str], float] = {}
        self._sessions: dict[int, float] = {}

    def changes(self) -> list[str]:
        """The events to send now (server-sent event text, one string each)."""
        rows = self.store.directory.robots_of(self.operator)
        sees_telemetry = may(self.operator.role, Permission.TELEMETRY)
        self.robot_ids = [row.id for row in rows]
        events: list[str] = []
        robots = [robot_public(self.store, row).model_dump() for row in rows]
        if robots != self._robots:
            self._robots = robots
            events.append(frame(robots, "robots"))
        for row in rows:
            for command in reversed(self.store.ledger.recent(row.id)):
                if self._versions.get(command.id) != command.version:
                    self._versions[command.id] = command.version
                    events.append(
                        frame(
                            CommandPublic.of(
                                command, row.name, with_result=sees_telemetry
                            ).model_dump(),
                            "command",
                        )
                    )
            stored = self.store.sessions.get(row.id)
            if stored is not None and self._sessions.get(row.id) != stored[1]:
                view, self._sessions[row.id] = stored
                view = shown_to(self.operator.role, view)  # a viewer: not what happened
                events.append(
                    frame({"robot": row.name, "view": view, "at_s": stored[1]}, "session")
                )
            if not sees_telemetry:
                continue
            fresh = {
                key: reading
                for key, reading in self.store.telemetry.latest(row.id).items()
                if self._telemetry.get((row.id, key)) != reading["at_s"]
            }
            if fresh:
                self._telemetry.update({(row.id, key): r["at_s"] for key, r in fresh.items()})
                events.append(frame({"robot": row.name, "values": fresh}, "telemetry"))
        return events

    async def wait(self, timeout_s: float) -> bool:
        """Until a command of one of the robots changes, or ``timeout_s`` (no thread held)."""
        return await self.store.doorbell.wait(self.robot_ids, timeout_s)


@router.get("/events")
async def events(request: Request, store: StoreDep, operator: CurrentOperator) -> Response:
    return event_stream(_stream(request, store, OperatorView(store, operator)))


async def _stream(request: Request, store: CloudStore, view: OperatorView) -> AsyncIterator[str]:
    token = request.headers.get("authorization", "").partition(" ")[2].strip()
    started_s = quiet_since_s = store.clock.now()
    while (
        store.clock.now() - started_s < STREAM_S
        and not store.closing.is_set()
        and not await request.is_disconnected()
        # a token revoked or expired meanwhile ends the stream (within the cache's 5 s)
        and (person := await run_in_threadpool(store.principals.authenticate, token)) is not None
    ):
        view.operator = person  # its role as it is now
        changes = await run_in_threadpool(view.changes)
        if changes:
            quiet_since_s = store.clock.now()
            yield "".join(changes)
        elif store.clock.now() - quiet_since_s >= KEEPALIVE_S:
            quiet_since_s = store.clock.now()
            yield KEEPALIVE
        await view.wait(TELEMETRY_EVERY_S)
