"""The view's web server: one page (engine/view/web/) for the live robot and for replays.

A Starlette app on the one web stack (:mod:`engine.web`), run by uvicorn in a thread
beside the robot:

- ``GET /`` the page, ``/view.js``, ``/view.css``, and ``/shared/`` what every page of
  vest shares (the stream client);
- ``GET /api/info`` live or replay (with the recording's length and its moments);
- ``GET /api/snapshot[?at=S]`` every tree with its nodes' statuses, the blackboard, the
  recent actions and the statistics (now, or at S seconds into a recording);
- ``GET /api/svg/TREE/VERSION`` the tree drawn by Graphviz as ``vest render`` draws it,
  node ``n3`` being the fourth node depth-first;
- ``GET /api/node?tree=T&version=V&node=N`` a recorded node's status changes;
- ``GET /api/events`` (live) server-sent events, one JSON change each;
- with buttons (``vest run --buttons``): ``GET /buttons`` the therapist's page,
  ``GET /api/buttons`` the buttons and what shows, ``GET /api/buttons/events`` the shown
  set as it changes, ``POST /api/press`` ``{"button": N}`` presses one (JSON only; the
  guard refuses another site's page: it cannot press for the therapist);
- on a simulated vest, beside the buttons: ``POST /api/act`` one scenario event without
  ``at`` (``{"squeeze": {"left_n": 6}}``), played now (:mod:`engine.buttons.acting`);
  422 with each problem's place when it is not one.

Every request asks for the server's token, on loopback too (:mod:`engine.web.guard`): the
address ``vest run --view`` prints carries it, and opening it keeps the browser in with a
cookie; a page of another site is refused.
"""

from __future__ import annotations

import json
import logging
import math
import re
import threading
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any, Protocol

from starlette.applications import Starlette
from starlette.middleware import Middleware
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, PlainTextResponse, Response
from starlette.routing import BaseRoute, Route

from engine.buttons.acting import ACTS, ActingNow
from engine.buttons.wizard import Wizard
from engine.errors import ConfigError
from engine.files.problems import LoadError
from engine.hardware.touch_pads import robot_pad_names
from engine.loader.tree_drawing import svg_of, without_title_and_legend
from engine.view.hub import Change, ViewHub
from engine.web.body_limit import BodyLimit
from engine.web.broadcast import Reader
from engine.web.guard import SecurityHeaders, TokenGuard, new_token
from engine.web.serving import ServerThread, address_of, listening_socket, shared_files
from engine.web.sse import CONNECTED, KEEPALIVE, KEEPALIVE_S, event_stream, frame

log = logging.getLogger(__name__)
WEB = Path(__file__).resolve().parent / "web"
STATIC = {
    "/": "index.html",
    "/view.js": "view.js",
    "/view.css": "view.css",
    "/buttons": "buttons.html",
    "/buttons.js": "buttons.js",
    "/buttons.css": "buttons.css",
}
MAX_STREAMS = 32
"""Live streams open at once (the view's and the buttons'); more are answered 503."""
MAX_PRESS_BYTES = 1024
PRESS_READ_TIMEOUT_S = 2.0
"""A press's body comes at once from the page; shorter than a server's grace on stopping."""


class ViewSource(Protocol):
    """What the page asks: the live hub (:class:`LiveSource`) or a recording."""

    def info(self) -> dict[str, Any]: ...

    def snapshot(self, at_s: float) -> Change: ...

    def dot(self, tree: str, version: int) -> str | None: ...

    def node_changes(self, tree: str, version: int, node: int) -> list[tuple[float, str, str]]: ...


class LiveSource:
    """The running robot, through its :class:`ViewHub`."""

    def __init__(self, hub: ViewHub) -> None:
        self.hub = hub

    def info(self) -> dict[str, Any]:
        return {"mode": "live"}

    def snapshot(self, at_s: float) -> Change:
        return self.hub.snapshot()

    def dot(self, tree: str, version: int) -> str | None:
        return self.hub.dot(tree, version)

    def node_changes(self, tree: str, version: int, node: int) -> list[tuple[float, str, str]]:
        return []  # the live page keeps each node's changes as they come


class ViewServer:
    """Serves ``source`` (and the therapist's buttons, when given a ``wizard``) on
    ``host``:``port`` (0: any free port) in a thread of its own; a ConfigError when it
    cannot listen there. Every request needs ``token`` (None: a new one)."""

    def __init__(
        self,
        source: ViewSource,
        *,
        host: str = "127.0.0.1",
        port: int = 8765,
        token: str | None = None,
        wizard: Wizard | None = None,
        acting: ActingNow | None = None,
    ) -> None:
        self.source = source
        self.token = token or new_token()
        self.wizard = wizard
        self.acting = acting if wizard is not None else None  # a page beside the buttons
        self._svg: dict[tuple[str, int], bytes] = {}
        self._svg_lock = threading.Lock()
        self._streams = 0  # open now; counted on the event loop
        try:
            sock = listening_socket(host, port, named=f"the view on {host}:{port}")
        except ConfigError as error:
            hint = "choose another with --view-port (0: any free one)"
            raise ConfigError(f"{error}; {hint}") from None
        self.host = host
        self.port = int(sock.getsockname()[1])
        self._server = ServerThread(self.app(), sock, "view")

    @property
    def url(self) -> str:
        """The page's address; on every address (0.0.0.0, ::), this machine's name."""
        return self.page_url("/")

    def page_url(self, page: str) -> str:
        """The address of ``page`` (``/``, ``/buttons``), with the token."""
        return address_of(self.host, self.port, page) + f"?token={self.token}"

    def start(self) -> None:
        self._server.start()

    def stop(self) -> None:
        """Tells every page the session ended (their streams end), then stops serving."""
        if isinstance(self.source, LiveSource):
            self.source.hub.close()
        if self.wizard is not None:
            self.wizard.close()
        self._server.stop()

    def app(self) -> Starlette:
        """The Starlette app: the routes above, behind the token guard."""
        files = [path for path in STATIC if self.wizard is not None or "buttons" not in path]
        routes: list[BaseRoute] = [Route(path, self._file) for path in files]
        routes.append(shared_files())
        routes += [
            Route("/api/info", self._info),
            Route("/api/snapshot", self._snapshot),
            Route("/api/svg/{rest:path}", self._drawing),
            Route("/api/node", self._node),
        ]
        if isinstance(self.source, LiveSource):
            routes.append(Route("/api/events", self._events))
        if self.wizard is not None:
            routes += [
                Route("/api/buttons", self._buttons),
                Route("/api/buttons/events", self._button_events),
                Route("/api/press", self._press, methods=["POST"]),
            ]
        if self.acting is not None:
            routes.append(Route("/api/act", self._act, methods=["POST"]))
        return Starlette(
            routes=routes,
            middleware=[
                Middleware(SecurityHeaders),
                Middleware(
                    TokenGuard, host=self.host, token=self.token, cookie=f"vest-{self.port}"
                ),
                Middleware(
                    BodyLimit, max_bytes=MAX_PRESS_BYTES, read_timeout_s=PRESS_READ_TIMEOUT_S
                ),
            ],
        )

    # -- the drawings --------------------------------------------------------------------
    def svg(self, tree: str, version: int) -> bytes | None:
        """The tree drawn by Graphviz (cached); None when unknown or Graphviz is missing."""
        key = (tree, version)
        with self._svg_lock:
            if key in self._svg:
                return self._svg[key]
        source = self.source.dot(tree, version)
        if source is None:
            return None
        drawn = svg_of(without_title_and_legend(source))  # the card names it; one legend
        if drawn is None:
            return None
        with self._svg_lock:
            self._svg[key] = drawn
        return drawn

    # -- the endpoints (plain functions run in uvicorn's threads; streams on its loop) ---
    def _file(self, request: Request) -> Response:
        return FileResponse(WEB / STATIC[request.url.path])

    def _info(self, request: Request) -> Response:
        return JSONResponse(self.source.info())

    def _snapshot(self, request: Request) -> Response:
        at = _number(request.query_params.get("at", "0"))
        if at is None:
            return PlainTextResponse("at is a number of seconds\n", status_code=400)
        return JSONResponse(self.source.snapshot(at))

    def _drawing(self, request: Request) -> Response:
        tree, _, version = request.path_params["rest"].rpartition("/")
        number = _count(version)
        drawn = self.svg(tree, number) if number is not None else None
        if drawn is None:
            return PlainTextResponse("no drawing of that tree (or no Graphviz)\n", 404)
        return Response(drawn, media_type="image/svg+xml")

    def _node(self, request: Request) -> Response:
        query = request.query_params
        version, node = _count(query.get("version", "")), _count(query.get("node", ""))
        if version is None or node is None:
            return PlainTextResponse("version and node are numbers\n", status_code=400)
        changes = self.source.node_changes(query.get("tree", ""), version, node)
        return JSONResponse([{"at": at, "status": s, "feedback": f} for at, s, f in changes])

    async def _events(self, request: Request) -> Response:
        assert isinstance(self.source, LiveSource)
        hub = self.source.hub
        return self._stream(_changes(hub, hub.changes.reader()))  # listening from now

    def _buttons(self, request: Request) -> Response:
        assert self.wizard is not None
        buttons = [button.to_json() for button in self.wizard.board.buttons]
        acting = self.acting
        acts = {"acts": list(ACTS), "pads": list(robot_pad_names(acting.config))} if acting else {}
        return JSONResponse({"buttons": buttons, "state": self.wizard.state(), **acts})

    async def _button_events(self, request: Request) -> Response:
        assert self.wizard is not None
        return self._stream(_button_states(self.wizard))

    def _stream(self, frames: AsyncIterator[str]) -> Response:
        """``frames`` as a stream, unless :data:`MAX_STREAMS` are open already (each page
        open costs the robot's process a little on every change). On the event loop."""
        if self._streams >= MAX_STREAMS:
            why = f"{MAX_STREAMS} pages are watching this robot already; close one\n"
            return PlainTextResponse(why, status_code=503)

        async def counted() -> AsyncIterator[str]:
            self._streams += 1  # once streaming: a page that left before is not counted
            try:
                async for text in frames:
                    yield text
            finally:
                self._streams -= 1

        return event_stream(counted())

    async def _press(self, request: Request) -> Response:
        wizard = self.wizard
        assert wizard is not None
        if not _sends_json(request):
            return PlainTextResponse('send JSON: {"button": N}\n', status_code=400)
        try:
            number = json.loads(await request.body()).get("button")
        except (ValueError, AttributeError, RecursionError):
            number = None
        if isinstance(number, bool) or not isinstance(number, int):
            return PlainTextResponse('send JSON: {"button": N}\n', status_code=400)
        if wizard.board.button(number) is None:
            return PlainTextResponse("no such button\n", status_code=404)
        if number not in wizard.state()["shown"]:
            return PlainTextResponse("that button is not shown now\n", status_code=409)
        button = wizard.press(number)
        assert button is not None
        return JSONResponse({"pressed": button.label}, status_code=202)

    async def _act(self, request: Request) -> Response:
        """Play one event on the simulated vest now: 202 with what it was, told in words."""
        acting = self.acting
        assert acting is not None
        if not _sends_json(request):
            return PlainTextResponse('send JSON: {"squeeze": {"left_n": 6}}\n', status_code=400)
        try:
            event = acting.act((await request.body()).decode("utf-8"))
        except UnicodeDecodeError:
            return PlainTextResponse("send the event as UTF-8 JSON\n", status_code=400)
        except LoadError as error:
            return PlainTextResponse(f"{error}\n", status_code=422)
        return JSONResponse({"acted": event.describe()}, status_code=202)


def _sends_json(request: Request) -> bool:
    """Whether the request says its body is JSON (what a page of another site cannot send
    without asking first: a press or an act is only ever the page's own)."""
    return request.headers.get("content-type", "").split(";")[0].strip() == "application/json"


async def _changes(hub: ViewHub, reader: Reader) -> AsyncIterator[str]:
    """The live changes, as they come. The first says to fetch the state (now that nothing
    published is missed: the page may have read it before it was listening); a page that
    fell behind is told so again."""
    yield CONNECTED + frame({"kind": "resync"})
    while (taken := await hub.changes.take(reader, KEEPALIVE_S)) is not None:
        if not taken.items:
            yield KEEPALIVE
            continue
        changes = taken.items
        if taken.overflowed:  # behind: fetch the state again (and hear of the end)
            ends = [c for c in changes if c.item.get("kind") == "end"]
            yield frame({"kind": "resync"}) + "".join(c.text(frame) for c in ends)
            continue
        yield "".join(change.text(frame) for change in changes)


async def _button_states(wizard: Wizard) -> AsyncIterator[str]:
    """The buttons shown now, then whenever they change, until the session ends; a page
    that fell behind gets the newest."""
    reader = wizard.states.reader()
    yield CONNECTED + frame(wizard.state())
    while (taken := await wizard.states.take(reader, KEEPALIVE_S)) is not None:
        if not taken.items:
            yield KEEPALIVE
            continue
        newest = taken.items[-1] if taken.overflowed else None
        for state in [newest] if newest is not None else taken.items:
            yield state.text(frame)
            if state.item.get("ended"):
                return


def _number(text: str) -> float | None:
    """A finite number of seconds, or None."""
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _count(text: str) -> int | None:
    """A whole number as the page sends it (ASCII digits, at most 9), or None."""
    return int(text) if re.fullmatch(r"[0-9]{1,9}", text) else None
