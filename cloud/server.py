"""Running the service under uvicorn, so that stopping it ends the operators' live streams
at once (they reconnect to the next service) instead of holding the shutdown up."""

from __future__ import annotations

import socket

import uvicorn
from fastapi import FastAPI

from cloud.services import CloudStore

GRACE_S = 3
"""How long requests in flight get to finish when the service stops."""


class CloudServer(uvicorn.Server):
    """A uvicorn server that tells the store it is closing before it waits for requests."""

    def __init__(self, config: uvicorn.Config, store: CloudStore) -> None:
        super().__init__(config)
        self.store = store

    async def shutdown(self, sockets: list[socket.socket] | None = None) -> None:
        self.store.begin_closing()
        await super().shutdown(sockets)


def server_for(app: FastAPI, **options: object) -> CloudServer:
    """A server for ``app`` (made by create_app); ``options`` go to uvicorn.Config."""
    config = uvicorn.Config(app, timeout_graceful_shutdown=GRACE_S, **options)  # type: ignore[arg-type]
    return CloudServer(config, app.state.store)
