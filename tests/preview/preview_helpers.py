"""Helpers for the tests of `rtcli preview` (test_preview.py, test_preview_browser.py): a small
animated scene that includes its materials, the preview run as a real process, and a page's
websocket read in Python as the page reads it (rtcli/preview/messages.py).

Every address is on the loopback. Waits have generous deadlines (the machine is shared); no
test asserts how long anything took.
"""

from __future__ import annotations

import asyncio
import json
import os
import signal
import subprocess
import sys
import threading
import time
from urllib.parse import parse_qs, urlsplit

import numpy as np

from rtcli.preview import messages

DEADLINE = 90                      # seconds: a first render may load or compile the engine

SCENE = """\
version: 1
include: [look.yaml]
image: {width: 96, height: 72}
animation: {fps: 1, frames: 3}
camera: {eye: [0, 1.6, -6], look_at: [0, 1, 0], fov: 46.83}
background: [0.4, 0.62, 1.0]
ambient: [1, 1, 1]
lights:
  - {position: [6, 10, -6], color: [0.75, 0.75, 0.75]}
  - {position: [-6, 7, -4], color: [0.45, 0.45, 0.45]}
objects:
  - {name: floor, plane: {point: [0, 0, 0], normal: [0, 1, 0]}, material: floor}
  - name: ball
    sphere: {center: [1.1, 1, 1.5], radius: 1}
    material: paint
    transform: [translate: {keys: {0: [0, 0, 0], 2: [-0.5, 0.5, 0]}}]
  - {name: glass ball, sphere: {center: [-1, 1, -0.6], radius: 1}, material: glass}
"""
LOOK = """\
materials:
  floor: {ambient: 0.1, diffuse: 0.8, specular: 0, texture: {checker: {colors: [[0.95, 0.9, 0.15], [0.9, 0.1, 0.1]]}}}
  paint: {ambient: 0.1, diffuse: %s, specular: 0.5, shininess: 40, reflection: 0.3}
  glass: {ambient: 0, diffuse: 0.004, specular: 0.9, shininess: 80, reflection: 0.1, transmission: 0.92, ior: 1.5,
          shadow: false}
"""
RED, GREEN = "[0.8, 0.1, 0.1]", "[0.1, 0.8, 0.1]"


def write_scene(folder, paint: str = RED):
    """scene.yaml and the look.yaml it includes, in `folder`; the scene's path."""
    (folder / "look.yaml").write_text(LOOK % paint)
    (folder / "scene.yaml").write_text(SCENE)
    return folder / "scene.yaml"


def save(path, text: str) -> None:
    """Write a file as an editor saves it: a new file renamed over the old one."""
    temporary = path.with_name(path.name + ".new")
    temporary.write_text(text)
    os.replace(temporary, path)


class Preview:
    """`rtcli preview SCENE --port 0 --no-browser` as a process in `folder` (`browser`: without
    --no-browser); stop() ends it with Ctrl-C (SIGINT) and returns its exit code and stderr."""

    def __init__(self, folder, *options: str, scene: str = "scene.yaml", browser: bool = False, env=None):
        self.folder = folder
        self.err_path = folder.parent / f"{folder.name}.stderr"
        self.err = open(self.err_path, "w")
        self.proc = subprocess.Popen([sys.executable, "-m", "rtcli", "preview", scene, "--port", "0", *options,
                                      *([] if browser else ["--no-browser"])], cwd=folder, stdout=subprocess.PIPE,
                                     stderr=self.err, text=True, start_new_session=True, env=env)
        self.lines: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()
        self.url = self.wait_for(lambda: self.lines and self.lines[0], "the URL")
        parts = urlsplit(self.url)
        self.base, self.host, self.port = f"{parts.scheme}://{parts.netloc}/", parts.hostname, parts.port
        self.token = parse_qs(parts.query)["token"][0]

    def _read(self) -> None:
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))

    def stderr(self) -> str:
        return self.err_path.read_text()

    def wait_for(self, what, doing: str, deadline: float = DEADLINE):
        """Poll until what() is true (and return it); fail if the process ends or the deadline passes."""
        end = time.monotonic() + deadline
        while not (result := what()):
            if self.proc.poll() is not None or time.monotonic() > end:
                self.kill()
                raise AssertionError(f"gave up waiting for {doing} (exit {self.proc.returncode}): {self.stderr()}")
            time.sleep(0.05)
        return result

    def page(self, path: str = "", **query) -> str:
        """The URL of one of the server's paths, with the token."""
        from urllib.parse import urlencode
        return self.base + path + "?" + urlencode({"token": self.token, **query})

    def stop(self) -> tuple[int, str]:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
        try:
            code = self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.kill()
            raise
        self.err.close()
        return code, self.stderr()

    def kill(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()


class Page:
    """A page's view of the websocket, kept in Python: the picture drawn from the tiles as the page
    draws them, the id map, and every JSON message."""

    def __init__(self):
        self.picture: np.ndarray | None = None
        self.ids: np.ndarray | None = None
        self.json: list[dict] = []

    def take(self, message) -> None:
        if isinstance(message, str):
            m = json.loads(message)
            self.json.append(m)
            if m["type"] == "scene" and (self.picture is None or self.picture.shape[:2] != (m["height"], m["width"])):
                self.picture = np.zeros((m["height"], m["width"], 3), np.uint8)
            return
        kind, *_, data = messages.read(message)
        if kind == messages.TILE:
            messages.paint(self.picture, message)
        else:
            self.ids = data.copy()

    def last(self, kind: str) -> dict | None:
        return next((m for m in reversed(self.json) if m["type"] == kind), None)

    def done(self, render: int | None = None) -> bool:
        """Whether a render (the given one, or any) is done."""
        return any(m["type"] == "done" and (render is None or m["render"] == render) for m in self.json)


async def follow(url: str, page: Page, until, send: list | None = None, deadline: float = DEADLINE,
                 origin: str | None = None) -> Page:
    """Open the websocket, send `send`'s messages, and read into `page` until until(page)."""
    import aiohttp
    headers = {"Origin": origin} if origin else {}
    async with aiohttp.ClientSession() as session, session.ws_connect(url, headers=headers) as ws:
        for m in send or ():
            await ws.send_str(json.dumps(m))
        end = time.monotonic() + deadline
        while not until(page):
            left = end - time.monotonic()
            if left <= 0:
                raise AssertionError(f"gave up reading the websocket: {page.json[-3:]}")
            msg = await ws.receive(timeout=left)
            if msg.type not in (aiohttp.WSMsgType.TEXT, aiohttp.WSMsgType.BINARY):
                raise AssertionError(f"the websocket closed: {msg}")
            page.take(msg.data)
    return page


def read_page(preview: Preview, until, send=None, page: Page | None = None, origin: str | None = None) -> Page:
    ws = preview.page("ws").replace("http://", "ws://", 1)
    return asyncio.run(follow(ws, page or Page(), until, send, origin=origin))
