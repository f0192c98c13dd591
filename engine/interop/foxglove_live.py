"""The live session for Foxglove and Lichtblick (``vest run --foxglove [PORT]``), through
Foxglove's own SDK (``foxglove-sdk``, MIT): its WebSocket server, on loopback only (it has
no token of its own: from another machine, an SSH tunnel), the same topics and JSON
schemas as ``vest replay --to mcap`` (:mod:`engine.interop.session_formats`), so a layout
made on a recording works live and the other way round.

A session reader: the scheduler's thread only hands each event over
(:class:`~engine.session.handoff.Handoff`, as the recorder does: never waited for, a full
queue drops and counts); a thread beside it gives them to the SDK, which sends them to the
connected clients.
"""

from __future__ import annotations

import json
import logging
from typing import Any

import foxglove

from engine.clock import Clock
from engine.errors import ConfigError
from engine.interop.session_formats import SCHEMAS
from engine.interop.session_topics import NodePaths, live_message
from engine.session.events import SessionEvent, TreeStarted
from engine.session.handoff import Handoff
from engine.web.guard import is_loopback

log = logging.getLogger(__name__)
CAPACITY = 50_000
"""Events the queue holds before it drops (seconds of the busiest session)."""


class FoxgloveLive:
    """Serves the session on ``host:port`` (loopback; port 0: any free one) to Foxglove
    and Lichtblick; times are the clock's (``epoch_offset_s`` turns them into seconds since
    the epoch)."""

    def __init__(self, host: str, port: int, clock: Clock, epoch_offset_s: float) -> None:
        if not is_loopback(host):
            raise ConfigError(
                f"--foxglove on {host}: Foxglove's server has no token, so vest serves it on "
                "this machine only (127.0.0.1); from another, use an SSH tunnel "
                "(ssh -L 8765:127.0.0.1:8765 robot)"
            )
        self.host, self.port, self.clock = host, port, clock
        self.epoch_offset_s = epoch_offset_s
        self._context = foxglove.Context()  # this session's channels alone, no global one
        self._server: Any = None
        self._channels: dict[str, foxglove.Channel] = {}
        self._paths: NodePaths = {}
        self._handoff = Handoff("foxglove", self._send, capacity=CAPACITY)

    def start(self) -> None:
        """Listens (ConfigError when the port is taken) and starts handing events over."""
        try:
            self._server = foxglove.start_server(
                name="vest", host=self.host, port=self.port, context=self._context
            )
        except RuntimeError as error:
            raise ConfigError(f"--foxglove {self.port}: cannot listen there ({error})") from None
        self.port = int(self._server.port)
        self._handoff.start()

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def on_event(self, event: SessionEvent) -> None:
        """The scheduler's thread: queued, never waited for."""
        self._handoff.put(event)

    def stop(self) -> None:
        self._handoff.close()
        if self._server is not None:
            self._server.stop()
            self._server = None
        if self._handoff.dropped:
            log.warning("foxglove: %d events were dropped", self._handoff.dropped)

    def _send(self, events: list[SessionEvent]) -> bool:
        for event in events:
            self._log(event)
        return True

    def _log(self, event: SessionEvent) -> None:
        """One event to its channel (made, with its MCAP schema's name, on first use)."""
        if isinstance(event, TreeStarted):
            for node in event.nodes:
                self._paths[(event.tree, event.version, node.index)] = (node.path, node.type)
            return
        found = live_message(event, self._paths)
        if found is None:
            return
        topic, schema, message = found
        channel = self._channels.get(topic)
        if channel is None:
            named = foxglove.Schema(  # named as in the MCAP export: one layout for both
                name=schema, encoding="jsonschema", data=json.dumps(SCHEMAS[schema]).encode()
            )
            channel = foxglove.Channel(
                topic, schema=named, message_encoding="json", context=self._context
            )
            self._channels[topic] = channel
        at_ns = round((event.t_s + self.epoch_offset_s) * 1e9)
        try:
            channel.log(message, log_time=at_ns)
        except Exception as error:  # a value the SDK cannot carry: the rest goes on
            log.warning("foxglove: %s not sent (%s)", topic, error)
