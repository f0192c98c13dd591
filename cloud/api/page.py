"""The operator's web page: plain HTML and JS modules from cloud/web/, no build step."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fastapi import FastAPI
from fastapi.responses import RedirectResponse
from starlette.responses import Response
from starlette.staticfiles import StaticFiles
from starlette.types import Scope

WEB = Path(__file__).resolve().parent.parent / "web"
PAGE = "/operator"
HEADERS = {
    # the page loads only its own files and talks only to its own service
    "Content-Security-Policy": "default-src 'self'; frame-ancestors 'none'; base-uri 'none'",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-cache",
}


class PageFiles(StaticFiles):
    """The page's files, each with the headers above."""

    async def get_response(self, path: str, scope: Scope) -> Response:
        response = await super().get_response(path, scope)
        response.headers.update(HEADERS)
        return response


def add_page(app: FastAPI) -> None:
    """Serve the page at /operator/, and send / there."""
    app.mount(PAGE, PageFiles(directory=WEB, html=True), name="operator-page")

    @app.get("/", include_in_schema=False)
    def home() -> Any:
        return RedirectResponse(f"{PAGE}/")
