"""The preview's web server (aiohttp): its page, a websocket per page, and the page's questions.

Security, as Jupyter's notebook server does it (docs/preview.md, Security):
- it listens on 127.0.0.1 unless told otherwise (`--host`, which warns);
- every request carries the token of the URL printed at start, as `?token=` or as the cookie
  the page gets with it: none is refused with 401, a wrong one with 403;
- a websocket's Origin, when the browser sends one, must be this server's own (403 otherwise),
  so another site's page open in the same browser cannot connect;
- the routes are fixed: the page and its bundled assets by name, this scene's renders and
  views by kind; no path is ever taken from a request;
- what a request may be is bounded (aiohttp's header limits, no body, small websocket
  messages), and so are the pages (MAX_PAGES at once) and what waits for each (PAGE_BYTES:
  a page that reads too slowly is skipped to the picture as it is, not queued without end).
"""

from __future__ import annotations

import asyncio
import collections
import contextlib
import functools
import hmac
import json
import logging
from importlib import resources

from aiohttp import WSCloseCode, WSMsgType, web
from aiohttp.http_exceptions import HttpProcessingError

from rtcli.api.results import png_bytes
from rtcli.errors import RtcliError, one_line
from rtcli.preview.session import Busy, Session

MAX_PAGES = 128                    # websockets open at once
PAGE_BYTES = 8 << 20               # bytes waiting to be sent to one page at most
MESSAGE_BYTES = 4096               # what a page may send in one websocket message
ANSWER_SECONDS = 300               # a question (an explanation, a view) is given up after this
ASSETS = {"preview.js": "text/javascript", "preview.css": "text/css"}
CSP = ("default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' blob: data:; "
       "connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'")


@functools.cache
def _asset(name: str) -> bytes:
    """A file of the page, read from rtcli's package once."""
    return resources.files("rtcli.preview").joinpath("assets", name).read_bytes()


class Page:
    """A page's websocket and what waits to be sent to it."""

    def __init__(self, ws: web.WebSocketResponse):
        self.ws, self.waiting, self.size = ws, collections.deque(), 0
        self.wake, self.behind = asyncio.Event(), False

    def put(self, message: bytes | str) -> None:
        """Queue a message; past PAGE_BYTES, drop what waits and send the picture as it is instead."""
        if self.size + len(message) > PAGE_BYTES:
            self.waiting.clear()
            self.size, self.behind = 0, True
        else:
            self.waiting.append(message)
            self.size += len(message)
        self.wake.set()

    async def pump(self, snapshot) -> None:
        """Send what waits, as the page reads it; after falling behind, the snapshot first. A page
        that has gone is the websocket handler's to forget."""
        try:
            await self._pump(snapshot)
        except ConnectionError:
            pass

    async def _pump(self, snapshot) -> None:
        while not self.ws.closed:
            await self.wake.wait()
            self.wake.clear()
            if self.behind:
                self.behind = False
                for message in snapshot():
                    self.put(message)
            while self.waiting and not self.ws.closed:
                message = self.waiting.popleft()
                self.size -= len(message)
                await (self.ws.send_bytes(message) if isinstance(message, bytes) else self.ws.send_str(message))


class Log(logging.Handler):
    """aiohttp's log as rtcli's lines: a request that breaks off or is malformed is the client's
    affair and said nowhere (the client got its 400); anything else is one line, not a traceback."""

    def __init__(self, say):
        super().__init__(logging.WARNING)
        self.say = say

    def emit(self, record: logging.LogRecord) -> None:
        error = record.exc_info[1] if record.exc_info else None
        if isinstance(error, (ConnectionError, HttpProcessingError)):
            return
        why = f": {type(error).__name__}: {error}" if error is not None else ""
        self.say(f"note: the preview's web server: {one_line(record.getMessage() + why)}")


@contextlib.contextmanager
def logging_to(say):
    """aiohttp's log through `say` (Log) within the block."""
    logger, handler = logging.getLogger("aiohttp"), Log(say)
    propagate = logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate


def encoded(message) -> bytes | str:
    return message if isinstance(message, bytes) else json.dumps(message)


class Preview:
    """The server's state: the session, the token, the pages connected."""

    def __init__(self, session: Session, token: str, origins: set[str], cookie: str, golden=None):
        self.session, self.token, self.origins, self.cookie, self.golden = session, token, origins, cookie, golden
        self.pages: set[Page] = set()
        self._snapshot: tuple[int, list] = (-1, [])

    def publish(self, message) -> None:
        """Send a message from the session to every page (in the server's thread)."""
        text = encoded(message)
        for page in self.pages:
            page.put(text)

    def snapshot(self) -> list:
        """The session's snapshot, encoded once for all the pages that arrive before it changes."""
        version = self.session.version
        if self._snapshot[0] != version:
            self._snapshot = (version, [encoded(m) for m in self.session.snapshot()])
        return self._snapshot[1]

    def app(self) -> web.Application:
        app = web.Application(middlewares=[self.guard], client_max_size=MESSAGE_BYTES)
        app.router.add_get("/", self.index)
        app.router.add_get("/static/{name}", self.asset)
        app.router.add_get("/ws", self.websocket)
        app.router.add_get("/explain.json", self.explain)
        app.router.add_get("/explain.txt", self.explain)
        app.router.add_get("/view/{kind}.png", self.view)
        app.router.add_get("/view/{kind}.json", self.view)
        app.router.add_get("/image.png", self.image)
        app.router.add_get("/against/{which}.png", self.against)
        app.on_shutdown.append(self.close_pages)
        return app

    async def close_pages(self, app) -> None:
        """Close every page's websocket, so that the server ends at once (the pages say so)."""
        for page in list(self.pages):
            await page.ws.close(code=WSCloseCode.GOING_AWAY, message=b"rtcli preview ended")

    @web.middleware
    async def guard(self, request: web.Request, handler):
        """The token on every request, the Origin when there is one; headers that keep the page
        to itself."""
        given = request.query.get("token") or request.cookies.get(self.cookie)
        if not given:
            raise web.HTTPUnauthorized(text="401: the preview's URL carries a token (?token=...): open the URL "
                                            "rtcli preview printed\n")
        if not hmac.compare_digest(given.encode(), self.token.encode()):
            raise web.HTTPForbidden(text="403: wrong token\n")
        origin = request.headers.get("Origin")
        if origin is not None and origin not in self.origins:
            raise web.HTTPForbidden(text="403: a page from another origin\n")
        response = await handler(request)
        response.headers.update({"Content-Security-Policy": CSP, "X-Content-Type-Options": "nosniff",
                                 "Referrer-Policy": "no-referrer", "Cache-Control": "no-store",
                                 "X-Frame-Options": "DENY"})
        return response

    async def index(self, request: web.Request) -> web.Response:
        response = web.Response(body=_asset("index.html"), content_type="text/html", charset="utf-8")
        if request.query.get("token"):
            response.set_cookie(self.cookie, self.token, httponly=True, samesite="Strict")
        return response

    async def asset(self, request: web.Request) -> web.Response:
        name = request.match_info["name"]
        if name not in ASSETS:
            raise web.HTTPNotFound()
        return web.Response(body=_asset(name), content_type=ASSETS[name], charset="utf-8")

    async def websocket(self, request: web.Request) -> web.WebSocketResponse:
        if len(self.pages) >= MAX_PAGES:
            raise web.HTTPServiceUnavailable(text=f"503: {MAX_PAGES} pages are open already\n")
        ws = web.WebSocketResponse(max_msg_size=MESSAGE_BYTES, heartbeat=30, compress=False)
        await ws.prepare(request)                  # a page gone by now raises ConnectionError: said nowhere (Log)
        page = Page(ws)
        for message in self.snapshot():
            page.put(message)
        self.pages.add(page)
        pump = asyncio.create_task(page.pump(self.snapshot))
        try:
            async for msg in ws:
                if msg.type == WSMsgType.TEXT:
                    self._told(msg.data)
                else:
                    break
        finally:
            self.pages.discard(page)
            pump.cancel()
            await ws.close()
        return ws

    def _told(self, text: str) -> None:
        """A page's message: {"frame": k} shows frame k. Anything else is ignored."""
        try:
            frame = json.loads(text).get("frame")
        except (ValueError, AttributeError):
            return
        if isinstance(frame, int) and not isinstance(frame, bool):
            try:
                self.session.ask("frame", frame)
            except Busy:
                pass

    async def _ask(self, what: str, *args):
        try:
            future = self.session.ask(what, *args)
        except Busy as e:
            raise web.HTTPServiceUnavailable(text=f"error: {e}\n") from None
        try:
            return await asyncio.wait_for(asyncio.wrap_future(future), ANSWER_SECONDS)
        except RtcliError as e:
            raise web.HTTPBadRequest(text=f"error: {one_line(str(e))}\n") from None

    async def explain(self, request: web.Request) -> web.Response:
        """`rtcli explain --json` of pixel (x, y) (explain.json), or its text (explain.txt)."""
        x, y = (_whole(request, name) for name in ("x", "y"))
        as_json, as_text = await self._ask("explain", x, y)
        if request.path.endswith(".json"):
            return web.Response(text=as_json + "\n", content_type="application/json")
        return web.Response(text=as_text + "\n", content_type="text/plain")

    async def view(self, request: web.Request) -> web.Response:
        """A debug view of the frame shown: its picture (.png) or its summary line (.json)."""
        kind = request.match_info["kind"]
        _, summary, png = await self._ask("view", kind)
        if request.path.endswith(".png"):
            return web.Response(body=png, content_type="image/png")
        return web.json_response({"kind": kind, "summary": summary})

    async def image(self, request: web.Request) -> web.Response:
        """The picture as it is now."""
        image = self.session.image
        if image is None:
            raise web.HTTPNotFound(text="404: nothing rendered yet\n")
        return web.Response(body=png_bytes(image), content_type="image/png")

    async def against(self, request: web.Request) -> web.Response:
        """The golden image, and the heat map and FLIP map of the last comparison with it."""
        pictures = self.golden.pictures if self.golden is not None else {}
        png = pictures.get(request.match_info["which"])
        if png is None:
            raise web.HTTPNotFound()
        return web.Response(body=png, content_type="image/png")


def _whole(request: web.Request, name: str) -> int:
    text = request.query.get(name, "")
    if not (text.isascii() and text.lstrip("-").isdigit() and len(text) < 12):
        raise web.HTTPBadRequest(text=f"error: {name} must be a whole number\n")
    return int(text)
