"""`rtcli preview --tev HOST:PORT`: the render streamed to a running tev viewer, as pbrt-v4 and
Mitsuba 3 stream theirs (docs/preview.md, tev).

tev's own client library (tevclient) speaks its protocol: one image per scene (and frame),
created with the channels R, G, B (the linear colors traced, which tev shows sRGB-encoded)
and a layer per debug view (normal.R/G/B, depth.Y, uv.R/G, albedo.R/G/B, bounces.Y, ids.Y);
each tile of each pass is sent as it is done, each block filled with its color, and the
views when the render is done. A thread sends them, so a slow tev never holds up the
render: when its queue is full, tiles are dropped, and the whole picture, sent at the end of
every render, puts them right.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable

import numpy as np

from rtcli.errors import RtcliError, shown

PORT = 14158                       # tev's default port
QUEUED = 256                       # packets waiting for tev at most
CHANNELS = {"normal": ("R", "G", "B"), "depth": ("Y",), "uv": ("R", "G"), "albedo": ("R", "G", "B"),
            "bounces": ("Y",), "ids": ("Y",)}


def address(text: str) -> tuple[str, int]:
    """(host, port) of HOST:PORT, [IPv6]:PORT or HOST (tev's port)."""
    host, colon, port = text.rpartition(":")
    if not colon or "]" in port:
        host, port = text, str(PORT)
    host = host.strip("[]")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise RtcliError(f"--tev {shown(text)}: give HOST:PORT, as 127.0.0.1:{PORT}")
    return host, int(port)


class Tev:
    """A connection to tev and the thread that feeds it."""

    def __init__(self, where: str, say: Callable[[str], None]):
        try:
            import tevclient  # the extra `preview`, for --tev only
        except ImportError:
            raise RtcliError("--tev needs the tevclient package (Python 3.11 or later): pip install -e "
                             "'.[preview]' in the rtcli folder") from None
        self.where, self.say = where, say
        self.ipc = tevclient.Ipc(*address(where))
        try:
            self.ipc.__enter__()
        except OSError as e:
            raise RtcliError(f"--tev {shown(where)}: cannot reach tev there ({e.strerror or e}); start tev "
                             f"first (it listens on 127.0.0.1:{PORT} unless told otherwise)") from None
        self.name, self.size, self.gone = None, (0, 0), False
        self.packets: queue.Queue = queue.Queue(QUEUED)
        threading.Thread(target=self._send, name="rtcli-tev", daemon=True).start()

    def begin(self, name: str, width: int, height: int) -> None:
        """A new render: its image in tev, made afresh with every channel."""
        if self.name is not None:
            self._put(self.ipc.close_image, self.name, wait=True)
        self.name, self.size = name, (width, height)
        channels = ["R", "G", "B"] + [f"{kind}.{c}" for kind, cs in CHANNELS.items() for c in cs]
        self._put(self.ipc.create_image, name, width, height, channels, wait=True)

    def tile(self, tile) -> None:
        """A tile of a pass, each grid point's linear color over its block (dropped when tev lags)."""
        b, (w, h) = tile.block, self.size
        x, y = int(tile.cols[0]), int(tile.rows[0])
        blocks = np.repeat(np.repeat(tile.colors, b, axis=0), b, axis=1)[:h - y, :w - x]
        self._put(self.ipc.update_image, self.name, blocks.astype(np.float32), ["R", "G", "B"], x, y)

    def image(self, linear: np.ndarray) -> None:
        """The finished render's linear colors, whole."""
        self._put(self.ipc.update_image, self.name, linear.astype(np.float32), ["R", "G", "B"], wait=True)

    def view(self, kind: str, data: np.ndarray) -> None:
        """A debug view (views.py) as its layer; 0 where the view has no value (a miss)."""
        data = np.asarray(data, dtype=np.float32)
        data = np.where(np.isfinite(data), data, np.float32(0))
        names = [f"{kind}.{c}" for c in CHANNELS[kind]]
        self._put(self.ipc.update_image, self.name, data, names, wait=True)

    def close(self) -> None:
        self._put(None, wait=True)

    def _put(self, send, *args, wait: bool = False) -> None:
        """Queue a packet; a tile (wait False) is dropped when the queue is full."""
        if not self.gone:
            try:
                self.packets.put((send, args), block=wait, timeout=5)
            except queue.Full:
                pass

    def _send(self) -> None:
        while True:
            send, args = self.packets.get()
            if send is None:
                break
            try:
                send(*args)
            except OSError as e:
                self.gone = True
                self.say(f"note: tev at {shown(self.where)} went away ({e.strerror or e}): the preview goes on "
                         "without it")
                break
        self.ipc.__exit__(None, None, None)
