"""`rtcli preview SCENE`: the scene in a browser page as it renders, coarse to fine, rendered again
at every save, and every pixel explained on a click (docs/preview.md).

    passes.py    the block-size preview as the first passes of the render, tile by tile
    session.py   the thread that owns the scene: loads and watches it, renders it, answers questions
    messages.py  what the page is sent: tiles and id maps as binary messages, the rest as JSON
    server.py    the web server (aiohttp): the page, its websocket, the token and the other guards
    against.py   --against GOLDEN.png: each finished render compared with it (rtcli.diff)
    tev.py       --tev HOST:PORT: the tiles and views streamed to the tev viewer
    assets/      the page: index.html, preview.js, preview.css (no library, nothing fetched elsewhere)

The server needs the extra `preview` (aiohttp; tevclient for --tev).
"""

from __future__ import annotations

import asyncio
import errno
import os
import secrets
import sys
import threading
from collections.abc import Callable

from rtcli.errors import RtcliError, shown
from rtcli.preview.against import Golden
from rtcli.preview.options import Options
from rtcli.preview.session import Session
from rtcli.preview.tev import Tev

__all__ = ["Options", "serve"]


def serve(scene: str, options: Options, *, host: str = "127.0.0.1", port: int = 0, browser: bool = True,
          against: str | None = None, tev: str | None = None, url: Callable[[str], None] = print,
          say: Callable[[str], None] = print) -> None:
    """Serve the preview of `scene` until interrupted: `url(URL)` is told the page's address, with
    its token; `say(line)` each render's line, error and note."""
    try:
        import aiohttp  # noqa: F401
    except ImportError:
        raise RtcliError("rtcli preview needs the extra `preview` (aiohttp): pip install -e '.[preview]' in the "
                         "rtcli folder (rtcli is not on the package index)") from None
    if not os.path.isfile(scene):
        raise RtcliError(f"{shown(scene)}: " + ("not a file" if os.path.exists(scene) else "no such file"))
    if host != "127.0.0.1":
        say(f"warning: --host {shown(host)}: the preview is served beyond 127.0.0.1; whoever reaches it there "
            "and has the URL's token sees this scene's renders")
    golden = Golden(against) if against is not None else None
    if tev is not None:
        tev = Tev(tev, say)
    try:
        asyncio.run(_serve(scene, options, host, port, browser, golden, tev, url, say))
    finally:
        if tev is not None:
            tev.close()


async def _serve(scene, options, host, port, browser, golden, tev, url, say) -> None:
    from aiohttp import web  # the extra `preview`, checked on entry to serve

    from rtcli.preview.server import Preview, logging_to
    loop, token = asyncio.get_running_loop(), secrets.token_urlsafe(24)
    session = Session(scene, options, lambda message: _post(loop, preview.publish, message), say, golden, tev)
    preview = Preview(session, token, set(), "", golden)
    runner = web.AppRunner(preview.app(), access_log=None, handle_signals=False, keepalive_timeout=60,
                           shutdown_timeout=1)
    await runner.setup()
    try:
        with logging_to(say):
            bound = await _listen(runner, host, port)
            preview.origins, preview.cookie = _origins(host, bound), f"rtcli-preview-{bound}"
            address = f"http://{_bracketed(host)}:{bound}/?token={token}"
            url(address)
            thread = threading.Thread(target=session.run, name="rtcli-preview", daemon=True)
            thread.start()
            if browser:
                loop.run_in_executor(None, _open, address, say)
            try:
                await asyncio.Event().wait()
            finally:
                session.stop()
                thread.join(timeout=2)
    finally:
        await runner.cleanup()


async def _listen(runner, host: str, port: int) -> int:
    """Listen on host:port (port 0: any free one); the port. A busy port is an RtcliError."""
    from aiohttp import web  # the extra `preview`
    site = web.TCPSite(runner, host, port)
    try:
        await site.start()
    except OSError as e:
        if e.errno == errno.EADDRINUSE:
            raise RtcliError(f"port {port} on {host} is busy: another program listens there; give another "
                             "--port, or --port 0 for any free one") from None
        raise RtcliError(f"cannot listen on {shown(host)} port {port}: {e.strerror or e}") from None
    return runner.addresses[0][1]


def _origins(host: str, port: int) -> set[str]:
    """The Origins a page of this server has: its address as printed, and the loopback's other names."""
    names = {host, "127.0.0.1", "localhost", "::1"}
    return {f"http://{_bracketed(name)}:{port}" for name in names}


def _bracketed(host: str) -> str:
    return f"[{host}]" if ":" in host else host


def _post(loop, publish, message) -> None:
    """Hand a message from the session's thread to the server's."""
    try:
        loop.call_soon_threadsafe(publish, message)
    except RuntimeError:                    # the loop has closed: the preview is ending
        pass


def _open(url: str, say: Callable[[str], None]) -> None:
    """Open the page in the user's browser ($BROWSER, else the system's), where there is a screen
    to show it: without one, Python would pick a text browser, which would take the terminal."""
    import webbrowser  # start-up: only when a browser is opened
    screen = sys.platform in ("darwin", "win32") or os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    if not (os.environ.get("BROWSER") or screen) or not webbrowser.open(url):
        say("note: no browser to open here: open the URL above in one")
