"""The operator's web page: plain HTML and JS modules from cloud/web/, no build step."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fastapi import FastAPI
from fastapi.responses import RedirectResponse
from starlette.staticfiles import StaticFiles

from engine.web.serving import shared_files

WEB = Path(__file__).resolve().parent.parent / "web"
PAGE = "/operator"


def add_page(app: FastAPI) -> None:
    """Serve the page at /operator/ (with the files every page of vest shares at
    /shared/), and send / there (the security headers are the app's,
    :class:`engine.web.guard.SecurityHeaders`)."""
    app.mount(PAGE, StaticFiles(directory=WEB, html=True), name="operator-page")
    app.router.routes.append(shared_files())

    @app.get("/", include_in_schema=False)
    def home() -> Any:
        return RedirectResponse(f"{PAGE}/")
