"""The tree editor's web server (``vest edit``): one page (engine/editor/web/) on the one web
stack (:mod:`engine.web`), in a thread of its own.

- ``GET /`` the page, ``/editor.js``, ``/editor.css``; ``/shared/`` what every page shares;
- ``GET /api/palette`` the nodes, their parameters as form fields, the robot's words;
- ``GET /api/files`` the folder's trees, subtrees, profiles and dialogs;
- ``GET /api/file?name=F`` a file's text, its version and, for a tree, its outline;
- ``POST /api/check`` ``{"file", "outline"}`` the text the outline makes, the validator's
  problems (each with the node it belongs to) and, when there are none, the drawing;
- ``POST /api/save`` ``{"file", "outline", "version", "over_problems"}`` writes it (409
  when the file changed on disk since ``version``, or when the change has problems the
  file has not and ``over_problems`` is false; ``version`` null for a new file);
- ``POST /api/try`` ``{"file", "outline", "version", "event"}`` runs the tree as it is on
  the page on the simulated vest with one event and answers its timeline (400 with why
  when the event or the run cannot be); ``POST /api/watch`` the same in real time under
  the live view, answering the view's address;
- ``POST /api/hear`` ``{"file", "outline", "version"}`` a dialog's phrases said and heard
  as the robot hears them (vest dialogs check --quick);
- ``GET /api/profiles`` what each profile sets (and the profiles that do not load);
  ``POST /api/profile`` ``{"profile", "setting", "value"}`` has a profile set a tree's
  setting (``value`` null: no longer), written in place in its file.

Bodies are JSON; every request asks for the token in the address ``vest edit`` prints, on
loopback too, and a page of another site is refused (:mod:`engine.web.guard`).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.middleware import Middleware
from starlette.requests import Request
from starlette.responses import FileResponse, JSONResponse, Response
from starlette.routing import BaseRoute, Route

from engine.editor.dialog_yaml import DialogText
from engine.editor.round_trip import PLAIN_WORD, OutlineError
from engine.editor.tree_yaml import TreeText
from engine.editor.workspace import MAX_FILE_BYTES, EditRefused, Workspace
from engine.errors import ConfigError
from engine.loader.node_sentences import node_sentence
from engine.loader.tree_drawing import dot_source, svg_of, without_title_and_legend
from engine.web.body_limit import BodyLimit
from engine.web.guard import SecurityHeaders, TokenGuard, new_token
from engine.web.serving import ServerThread, address_of, listening_socket, shared_files

WEB = Path(__file__).parent / "web"
STATIC = {"/": "editor.html", "/editor.js": "editor.js", "/editor.css": "editor.css"}
READ_TIMEOUT_S = 5.0


TryOut = Callable[[str, str, object], list[str]]
"""Runs a tree's text (its file's name) with an event the page asked for: the timeline's
lines; a ValueError saying why not."""
Watch = Callable[[str, str, object, str], str]
"""Runs a tree's text in real time with an event under the live view on a host: the
view's address; a ValueError saying why not."""
HearCheck = Callable[[str, str], list[str]]
"""Says a dialog's phrases as the robot would hear them (its text, its file's name): the
check's lines; a ValueError saying why not."""


class EditorServer:
    """Serves ``workspace`` with ``palette`` on ``host``:``port`` (0: any free port); a
    ConfigError when it cannot listen there. Every request needs ``token`` (None: a new
    one)."""

    def __init__(
        self,
        workspace: Workspace,
        palette: dict[str, Any],
        *,
        host: str = "127.0.0.1",
        port: int = 8766,
        token: str | None = None,
        try_out: TryOut | None = None,
        hear_check: HearCheck | None = None,
        watch: Watch | None = None,
    ) -> None:
        self.try_out, self.hear_check, self.watch = try_out, hear_check, watch
        self.workspace, self.palette, self.host = workspace, palette, host
        self.token = token or new_token()
        try:
            sock = listening_socket(host, port, named=f"the editor on {host}:{port}")
        except ConfigError as error:
            raise ConfigError(f"{error}; choose another with --port (0: any free one)") from None
        self.port = int(sock.getsockname()[1])
        self._server = ServerThread(self.app(), sock, "editor")

    @property
    def url(self) -> str:
        return address_of(self.host, self.port, "/") + f"?token={self.token}"

    def start(self) -> None:
        self._server.start()

    def stop(self) -> None:
        self._server.stop()

    def app(self) -> Starlette:
        routes: list[BaseRoute] = [Route(path, self._file) for path in STATIC]
        routes += [
            shared_files(),
            Route("/api/palette", lambda _: JSONResponse(self.palette)),
            Route("/api/files", lambda _: JSONResponse(self.workspace.files())),
            Route("/api/profiles", self._profiles),
            Route("/api/priorities", lambda _: JSONResponse(self.workspace.priorities())),
            Route("/api/file", self._read),
            Route("/api/check", self._check, methods=["POST"]),
            Route("/api/save", self._save, methods=["POST"]),
            Route("/api/profile", self._profile, methods=["POST"]),
        ]
        if self.try_out is not None:
            routes.append(Route("/api/try", self._try, methods=["POST"]))
        if self.hear_check is not None:
            routes.append(Route("/api/hear", self._hear, methods=["POST"]))
        if self.watch is not None:
            routes.append(Route("/api/watch", self._watch, methods=["POST"]))
        return Starlette(
            routes=routes,
            middleware=[
                Middleware(SecurityHeaders),
                Middleware(
                    TokenGuard, host=self.host, token=self.token, cookie=f"vest-{self.port}"
                ),
                Middleware(BodyLimit, max_bytes=2 * MAX_FILE_BYTES, read_timeout_s=READ_TIMEOUT_S),
            ],
        )

    # -- endpoints (plain functions run in uvicorn's threads) ---------------------------
    def _file(self, request: Request) -> Response:
        return FileResponse(WEB / STATIC[request.url.path])

    def _profiles(self, _: Request) -> Response:
        profiles, problems = self.workspace.profiles()
        return JSONResponse({"profiles": profiles, "problems": problems})

    def _read(self, request: Request) -> Response:
        name = request.query_params.get("name", "")
        try:
            text, version = self.workspace.read(name)
        except EditRefused as refused:
            return _refused(refused)
        answer: dict[str, Any] = {"file": name, "text": text, "version": version, "outline": None}
        answer["kind"] = "tree"
        try:
            answer["outline"] = TreeText(text, self.workspace.registry).outline()
        except OutlineError as error:
            answer["kind"], answer["why_not"] = "dialog", str(error)
        if answer["outline"] is None:
            try:
                answer["outline"] = DialogText(text).outline()
            except OutlineError:
                answer["kind"] = "other"  # a profile, buttons: shown as text
        return JSONResponse(answer)

    async def _check(self, request: Request) -> Response:
        return await self._answer(request, self._checked)

    async def _save(self, request: Request) -> Response:
        return await self._answer(request, self._saved)

    async def _profile(self, request: Request) -> Response:
        return await self._answer(request, self._set_in_profile, of_a_file=False)

    async def _try(self, request: Request) -> Response:
        return await self._answer(request, self._tried)

    async def _hear(self, request: Request) -> Response:
        return await self._answer(request, self._heard)

    async def _watch(self, request: Request) -> Response:
        return await self._answer(request, self._watched)

    async def _answer(
        self,
        request: Request,
        work: Callable[[dict[str, Any]], dict[str, Any]],
        *,
        of_a_file: bool = True,
    ) -> Response:
        """The page's JSON body, worked on in a thread of the pool (a long check or try
        never holds up the server's other requests); a refusal in words."""
        try:
            body = await self._body(request, of_a_file=of_a_file)
            return JSONResponse(await run_in_threadpool(work, body))
        except EditRefused as refused:
            return _refused(refused)

    # -- the work (in the pool's threads) -------------------------------------------------
    def _checked(self, body: dict[str, Any]) -> dict[str, Any]:
        name, text = self._text_of(body)
        problems, tree = self.workspace.checked(name, text)
        words = {} if "rules" in body["outline"] else self._words(body["outline"].get("root"))
        return {
            "text": text,
            "problems": _with_nodes(problems, text, self.workspace),
            "svg": _drawing(tree),
            "words": words,
        }

    def _words(self, root: Any) -> dict[str, str]:
        """Each leaf of the outline said in words, by its place (``root/0/child``), as the
        page's outline names places."""
        registry, catalogue = self.workspace.registry, self.workspace.registry.catalogue()
        found: dict[str, str] = {}
        stack: list[tuple[Any, str]] = [(root, "root")]
        while stack:
            node, path = stack.pop()
            if not isinstance(node, dict) or not isinstance(node.get("type"), str):
                continue
            args: dict[str, Any] = node["args"] if isinstance(node.get("args"), dict) else {}
            sentence = node_sentence(node["type"], args, catalogue)
            if sentence is not None:
                found[path] = sentence
            declared = registry.get(node["type"])
            one = declared is not None and declared.children == "one"
            children: list[Any] = node["children"] if isinstance(node.get("children"), list) else []
            stack += [(c, f"{path}/{'child' if one else i}") for i, c in enumerate(children)]
        return found

    def _saved(self, body: dict[str, Any]) -> dict[str, Any]:
        name, text = self._text_of(body)
        version = body.get("version")
        if version is not None and not isinstance(version, str):
            raise EditRefused(400, "version is the text the file's reading gave, or null")
        saved = self.workspace.save(
            name, text, version, over_problems=body.get("over_problems") is True
        )
        return {"version": saved.version, "problems": saved.problems}

    def _set_in_profile(self, body: dict[str, Any]) -> dict[str, Any]:
        profile, setting = body.get("profile"), body.get("setting")
        if not isinstance(profile, str) or not isinstance(setting, str):
            raise EditRefused(400, "profile and setting are names")
        self.workspace.set_in_profile(profile, setting, body.get("value"))
        profiles, problems = self.workspace.profiles()
        return {"profiles": profiles, "problems": problems}

    def _tried(self, body: dict[str, Any]) -> dict[str, Any]:
        assert self.try_out is not None
        name, text = self._runnable(body)
        try:
            return {"timeline": self.try_out(name, text, body.get("event"))}
        except ValueError as why:
            raise EditRefused(400, str(why)) from None

    def _watched(self, body: dict[str, Any]) -> dict[str, Any]:
        assert self.watch is not None
        name, text = self._runnable(body)
        try:
            return {"url": self.watch(name, text, body.get("event"), self.host)}
        except ValueError as why:
            raise EditRefused(400, str(why)) from None

    def _heard(self, body: dict[str, Any]) -> dict[str, Any]:
        assert self.hear_check is not None
        name, text = self._text_of(body)
        try:
            return {"lines": self.hear_check(name, text)}
        except ValueError as why:
            raise EditRefused(400, str(why)) from None

    async def _body(self, request: Request, *, of_a_file: bool = True) -> dict[str, Any]:
        """The page's JSON body (``of_a_file``: naming a file and holding an outline);
        EditRefused (400, 403) for one that is not the page's."""
        kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
        if kind != "application/json":
            raise EditRefused(400, 'send JSON: {"file": ..., "outline": ...}')
        try:
            body = json.loads(await request.body())
        except (ValueError, RecursionError):
            raise EditRefused(400, "the body is not JSON") from None
        if not isinstance(body, dict):
            raise EditRefused(400, "send a JSON object")
        if not of_a_file:
            return body
        if not isinstance(body.get("file"), str):
            raise EditRefused(400, 'send JSON: {"file": ..., "outline": ...}')
        if not isinstance(body.get("outline"), dict):
            raise EditRefused(400, "outline: the tree or dialog as the page holds it")
        return body

    def _runnable(self, body: dict[str, Any]) -> tuple[str, str]:
        """:meth:`_text_of`, refused (400) when running it would read outside the folder."""
        name, text = self._text_of(body)
        why = self.workspace.leads_outside(name, text)
        if why is not None:
            raise EditRefused(400, why)
        return name, text

    def _text_of(self, body: dict[str, Any]) -> tuple[str, str]:
        """The file named and the text the body's outline makes of the file as it is."""
        name: str = body["file"]
        outline: dict[str, Any] = body["outline"]
        self.workspace.path_of(name)  # refused before anything is read
        try:
            base = self.workspace.read(name)[0] if body.get("version") is not None else None
        except EditRefused as refused:
            if refused.status != 404:
                raise
            base = None
        try:
            if "rules" in outline:  # a dialog's questions and answers
                dialog = DialogText(base or f"dialog: {json.dumps(Path(name).stem)}\nrules: []\n")
                return name, dialog.written(outline)
            tree = TreeText(base or _skeleton(outline), self.workspace.registry)
            return name, tree.written(outline)
        except (OutlineError, RecursionError) as error:
            why = "nested too deep" if isinstance(error, RecursionError) else str(error)
            raise EditRefused(400, f"{name}: {why}") from None


def _skeleton(outline: dict[str, Any]) -> str:
    """The text a new tree starts from (its settings and root come from the outline)."""
    settings = outline.get("settings") if isinstance(outline.get("settings"), dict) else {}
    name = str((settings or {}).get("name") or "new_tree")
    shown = name if PLAIN_WORD.fullmatch(name) else json.dumps(name)
    return f"name: {shown}\nrate_hz: 10\nroot:\n  Sequence: []\n"


def _with_nodes(
    problems: list[dict[str, Any]], text: str, workspace: Workspace
) -> list[dict[str, Any]]:
    """Each problem in the edited file with the node (its id in ``text``) it belongs to."""
    try:
        lines = TreeText(text, workspace.registry).node_lines()
    except OutlineError:
        lines = []
    for problem in problems:  # a problem above the root (a setting) is no node's
        before = [ident for line, ident in lines if line <= problem["line"]]
        problem["node"] = before[-1] if problem["here"] and before else None
    return problems


def _drawing(tree: Any) -> str | None:
    if tree is None:
        return None
    drawn = svg_of(without_title_and_legend(dot_source(tree)))
    return drawn.decode("utf-8") if drawn is not None else None


def _refused(refused: EditRefused) -> Response:
    body = {"message": str(refused), "problems": refused.problems}
    return JSONResponse(body, status_code=refused.status)
