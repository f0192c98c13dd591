"""The service: ``create_app(settings)`` builds it, with its store, on a clock."""

from __future__ import annotations

import logging
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager

from fastapi import FastAPI, Request, Response
from fastapi.exception_handlers import http_exception_handler
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from sqlalchemy.exc import SQLAlchemyError
from starlette.exceptions import HTTPException as StarletteHTTPException

from cloud.api import commands, events, presses, robot_side, robots
from cloud.api.page import add_page
from cloud.api.schemas import ERRORS
from cloud.services import CloudStore
from cloud.settings import Settings
from cloud.store.writer import Upkeep
from engine.clock import Clock, EpochClock
from engine.web.body_limit import BodyLimit
from engine.web.guard import SecurityHeaders

API = "/api/v1"


log = logging.getLogger("vest.cloud")


def create_app(
    settings: Settings, *, clock: Clock | None = None, store: CloudStore | None = None
) -> FastAPI:
    """The FastAPI app; ``store`` is opened from ``settings`` unless given (and then closed
    with the app). While the app runs, its upkeep runs every ``settings.flush_s``."""
    owned = store is None
    store = store or CloudStore.open(settings, clock or EpochClock())

    @asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        upkeep = Upkeep(store.telemetry, store.ledger, store.clock, settings.flush_s)
        try:
            yield
        finally:
            upkeep.close()
            if owned:
                store.close()

    app = FastAPI(title="vest cloud", version="1", lifespan=lifespan)
    app.state.store = store
    for router in (
        robots.me,
        robots.router,
        commands.router,
        presses.router,
        robot_side.router,
        events.router,
    ):
        app.include_router(router, prefix=API, responses=ERRORS)
    add_page(app)

    app.add_middleware(BodyLimit, max_bytes=settings.max_body_bytes)
    app.add_middleware(SecurityHeaders)

    @app.exception_handler(RequestValidationError)
    async def bad_body(request: Request, error: RequestValidationError) -> JSONResponse:
        problems = [
            {
                "field": "body"  # its location is a character offset, not a field
                if item["type"] == "json_invalid"
                else ".".join(str(part) for part in item["loc"][1:]) or "body",
                "message": item["msg"],
            }
            for item in error.errors()
        ]
        return JSONResponse({"detail": problems}, status_code=422)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, error: StarletteHTTPException) -> Response:
        if error.status_code == 400:  # JSON that parses nowhere: nested too deep, huge numbers
            problem = {"field": "body", "message": "not JSON this service reads (too deep?)"}
            return JSONResponse({"detail": [problem]}, status_code=422)
        return await http_exception_handler(request, error)

    @app.exception_handler(SQLAlchemyError)
    @app.exception_handler(OSError)
    async def cannot_store(request: Request, error: Exception) -> JSONResponse:
        """The database or the disk failed (full, gone): 503 with why, as JSON the page
        and the robot read (nothing was changed; ask again later)."""
        log.error("%s %s failed: %s", request.method, request.url.path, error)
        reason = str(getattr(error, "orig", None) or error).splitlines()[0][:200]
        return JSONResponse(
            {"detail": f"the service cannot store this now ({reason}); try again later"},
            status_code=503,
        )

    return app
