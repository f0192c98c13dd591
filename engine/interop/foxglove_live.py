"""The live session for Foxglove and Lichtblick (``vest run --foxglove [PORT]``): Foxglove's
WebSocket protocol (``foxglove.websocket.v1``, and ``foxglove.sdk.v1`` as Foxglove's SDK
names it), served on vest's one web stack, behind the token guard every page of vest has
(:mod:`engine.web.guard`): the address vest prints carries the token, and a page of
another site is refused unless it was named with ``--foxglove-origin``. On loopback only
(from another machine, an SSH tunnel). The topics and JSON schemas are those of ``vest
replay --to mcap`` (:mod:`engine.interop.session_formats`), so a layout made on a
recording works live and the other way round.

A reader of the consent gate's kept exit: the scheduler's thread only hands each event
over (:class:`~engine.session.handoff.Handoff`, as the recorder does: never waited for, a
full queue drops and counts); a thread beside it turns events into messages on one
bounded broadcast (:mod:`engine.web.broadcast`) that every connected client reads on the
server's event loop, each sent only the channels it subscribed to.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import struct
import threading
from collections.abc import Collection
from dataclasses import dataclass
from typing import Any, TypeGuard

from starlette.applications import Starlette
from starlette.middleware import Middleware
from starlette.routing import WebSocketRoute
from starlette.websockets import WebSocket, WebSocketDisconnect

from engine.clock import Clock
from engine.errors import ConfigError
from engine.interop.session_formats import SCHEMAS
from engine.interop.session_topics import NodePaths, live_message
from engine.session.events import SessionEvent, TreeStarted
from engine.session.handoff import Handoff
from engine.session.json_values import json_value
from engine.web.broadcast import Broadcast
from engine.web.guard import TokenGuard, is_loopback, new_token, refuse_websocket
from engine.web.serving import ServerThread, listening_socket

log = logging.getLogger(__name__)
CAPACITY = 50_000
"""Events the queue holds before it drops (seconds of the busiest session)."""
SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")
MAX_CLIENTS = 16
MESSAGE_DATA = 0x01
"""The binary opcode of a message: then the subscription (uint32) and the log time (uint64
ns since the epoch), little-endian, then the message."""
WAKE_EVERY_S = 15.0


@dataclass(frozen=True)
class Channel:
    """A topic as advertised: its number, its schema's name (as in the MCAP export)."""

    id: int
    topic: str
    schema: str

    def advertised(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "topic": self.topic,
            "encoding": "json",
            "schemaName": self.schema,
            "schema": json.dumps(SCHEMAS[self.schema]),
            "schemaEncoding": "jsonschema",
        }


@dataclass(frozen=True)
class Item:
    """What every client is told: a channel's first use (``data`` None) or a message."""

    channel: Channel
    at_ns: int = 0
    data: bytes | None = None


class FoxgloveLive:
    """Serves the session on ``host:port`` (loopback; port 0: any free one) to Foxglove
    and Lichtblick; times are the clock's (``epoch_offset_s`` turns them into seconds since
    the epoch). Every connection needs ``token`` (None: a new one); pages of ``origins``
    (another site's, such as Foxglove's web app) may connect with it too."""

    def __init__(
        self,
        host: str,
        port: int,
        clock: Clock,
        epoch_offset_s: float,
        *,
        token: str | None = None,
        origins: Collection[str] = (),
    ) -> None:
        if not is_loopback(host):
            raise ConfigError(
                f"--foxglove on {host}: vest serves Foxglove on this machine only "
                "(127.0.0.1); from another, use an SSH tunnel (ssh -L 8765:127.0.0.1:8765 robot)"
            )
        self.host, self.clock = host, clock
        self.epoch_offset_s = epoch_offset_s
        self.token = token or new_token()
        self._paths: NodePaths = {}
        self._channels: dict[str, Channel] = {}
        self._channels_lock = threading.Lock()
        self._items: Broadcast[Item] = Broadcast(clock, CAPACITY)
        self._handoff = Handoff("foxglove", self._send, capacity=CAPACITY)
        self._clients = 0  # connected now; counted on the event loop
        sock = listening_socket(host, port, named=f"--foxglove {port}")
        self.port = int(sock.getsockname()[1])
        guard = Middleware(
            TokenGuard, host=host, token=self.token, cookie=f"vest-{self.port}", origins=origins
        )
        app = Starlette(routes=[WebSocketRoute("/", self._client)], middleware=[guard])
        self._server = ServerThread(app, sock, "foxglove")

    def start(self) -> None:
        """Serves, and starts handing events over."""
        self._server.start()
        self._handoff.start()

    @property
    def url(self) -> str:
        """The address Foxglove opens, with the token."""
        return f"ws://{self.host}:{self.port}/?token={self.token}"

    def on_event(self, event: SessionEvent) -> None:
        """The scheduler's thread: queued, never waited for."""
        self._handoff.put(event)

    def stop(self) -> None:
        self._handoff.close()
        self._items.close()  # every client's connection ends
        self._server.stop()
        if self._handoff.dropped:
            log.warning("foxglove: %d events were dropped", self._handoff.dropped)

    # -- the hand-over thread -------------------------------------------------------------
    def _send(self, events: list[SessionEvent]) -> bool:
        for event in events:
            if isinstance(event, TreeStarted):
                for node in event.nodes:
                    self._paths[(event.tree, event.version, node.index)] = (node.path, node.type)
                continue
            found = live_message(event, self._paths)
            if found is None:
                continue
            topic, schema, message = found
            channel = self._channels.get(topic)
            if channel is None:  # advertised to every client as it first carries something
                with self._channels_lock:
                    channel = Channel(len(self._channels) + 1, topic, schema)
                    self._channels[topic] = channel
                self._items.publish(Item(channel))
            at_ns = max(0, round((event.t_s + self.epoch_offset_s) * 1e9))
            data = json.dumps(json_value(message)).encode()  # NaN as null, as everywhere
            self._items.publish(Item(channel, at_ns, data))
        return True

    def _known_channels(self) -> list[Channel]:
        with self._channels_lock:
            return list(self._channels.values())

    # -- a client (the server's event loop) ----------------------------------------------
    async def _client(self, websocket: WebSocket) -> None:
        offered = websocket.scope.get("subprotocols") or []
        chosen = next((name for name in SUBPROTOCOLS if name in offered), None)
        if chosen is None:
            why = f"ask for Foxglove's WebSocket protocol: {' or '.join(SUBPROTOCOLS)}"
            await refuse_websocket(websocket.scope, websocket.send, 400, why)
            return
        if self._clients >= MAX_CLIENTS:
            why = f"{MAX_CLIENTS} clients are watching this robot already; close one"
            await refuse_websocket(websocket.scope, websocket.send, 503, why)
            return
        await websocket.accept(subprotocol=chosen)
        self._clients += 1
        try:
            await self._serve(websocket)
        except (WebSocketDisconnect, RuntimeError, OSError):
            pass  # the client left while it was being told something
        finally:
            self._clients -= 1

    async def _serve(self, websocket: WebSocket) -> None:
        reader = self._items.reader()  # from now on; what came before is advertised below
        info = {"op": "serverInfo", "name": "vest", "capabilities": [], "metadata": {}}
        await websocket.send_text(json.dumps(info | {"supportedEncodings": ["json"]}))
        told: set[int] = set()
        await self._advertise(websocket, self._known_channels(), told)
        subscribed: dict[int, int] = {}  # channel -> the client's subscription
        listening = asyncio.ensure_future(_listen(websocket, subscribed))
        try:
            while not listening.done():
                taken = await self._items.take(reader, WAKE_EVERY_S)
                if taken is None:  # the session ended
                    break
                if taken.overflowed:  # fell behind: channels made meanwhile are told again
                    await self._advertise(websocket, self._known_channels(), told)
                for published in taken.items:
                    item = published.item
                    if item.data is None:
                        await self._advertise(websocket, [item.channel], told)
                    elif (subscription := subscribed.get(item.channel.id)) is not None:
                        head = struct.pack("<BIQ", MESSAGE_DATA, subscription, item.at_ns)
                        await websocket.send_bytes(head + item.data)
        finally:
            listening.cancel()
            with contextlib.suppress(asyncio.CancelledError, WebSocketDisconnect):
                await listening
        with contextlib.suppress(RuntimeError, WebSocketDisconnect):
            await websocket.close()

    async def _advertise(
        self, websocket: WebSocket, channels: list[Channel], told: set[int]
    ) -> None:
        new = [channel for channel in channels if channel.id not in told]
        if new:
            told.update(channel.id for channel in new)
            message = {"op": "advertise", "channels": [c.advertised() for c in new]}
            await websocket.send_text(json.dumps(message))


async def _listen(websocket: WebSocket, subscribed: dict[int, int]) -> None:
    """The client's subscriptions as it sends them, until it leaves. What the protocol
    allows beyond (advertising its own channels, parameters, services) is declined by
    advertising no capability; anything else is told back as a status, never raised."""
    while True:
        message = await websocket.receive()
        if message["type"] == "websocket.disconnect":
            return
        text = message.get("text")
        try:
            request = json.loads(text) if isinstance(text, str) else None
        except ValueError:
            request = None
        if not isinstance(request, dict):
            await _status(websocket, "vest takes JSON requests: subscribe and unsubscribe")
            continue
        op = request.get("op")
        if op == "subscribe" and isinstance(request.get("subscriptions"), list):
            for asked in request["subscriptions"]:
                if not isinstance(asked, dict):
                    continue
                channel, number = asked.get("channelId"), asked.get("id")
                if _whole(channel) and _whole(number):
                    subscribed[channel] = number
        elif op == "unsubscribe" and isinstance(request.get("subscriptionIds"), list):
            gone = {s for s in request["subscriptionIds"] if _whole(s)}
            for channel, subscription in list(subscribed.items()):
                if subscription in gone:
                    del subscribed[channel]
        else:
            await _status(websocket, f"vest does not take {str(op)[:40]!r} requests")


async def _status(websocket: WebSocket, message: str) -> None:
    await websocket.send_text(json.dumps({"op": "status", "level": 1, "message": message}))


def _whole(value: Any) -> TypeGuard[int]:
    """A number the protocol carries as uint32."""
    return isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 2**32
