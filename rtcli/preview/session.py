"""The scene a preview shows: loaded, rendered pass by pass, watched, and asked about.

One thread owns the scene (the model, its engine, its BVH are not shared): it loads the
scene file as `rtcli render --watch` does (rendering/watch.py: the stamps of every file read, meshes
kept from one load to the next), renders it pass by pass (passes.py), and between two tiles
answers what the pages ask (a pixel's explanation, a debug view, another frame) and looks
at the files. A save stops the render after the tile at hand and starts the next one; a
broken edit publishes its one-line error and keeps the last good picture.

What it publishes (messages.py) goes through `publish`, which the server hands to every
page; `snapshot()` is what a page that arrives late is sent first.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import os
import queue
import threading
import time
from collections.abc import Callable

import numpy as np

from rtcli.api import explain, signature, view
from rtcli.api.loading import load_file, of_loaded
from rtcli.api.results import RenderStats, png_bytes
from rtcli.errors import RtcliError, error_line, one_line, plural, shown
from rtcli.inspect.checks import object_rows
from rtcli.inspect.lint import lines
from rtcli.inspect.views import KINDS as VIEWS
from rtcli.inspect.views import picture, summary
from rtcli.preview import messages
from rtcli.preview.options import Options
from rtcli.preview.passes import Progressive, passes
from rtcli.rendering.tiles import Job
from rtcli.rendering.watch import Changes, recording
from rtcli.scenefile.reuse import Kept

POLL = 0.05                        # seconds between looks at the scene's files
MAX_IDS = 65535                    # objects a signature's 16-bit ids tell apart (api.check_ids)
PENDING = 16                       # questions waiting for the thread at most; more are refused (Busy)


class Busy(RtcliError):
    """Too many questions wait already."""


class Session:
    """A scene file previewed: run() is the thread's body, until stop()."""

    def __init__(self, path: str, options: Options, publish: Callable, say: Callable[[str], None],
                 golden=None, tev=None):
        self.path, self.options, self.publish, self.say = path, options, publish, say
        self.version = 0                             # how many messages were published: the snapshot's age
        self.golden, self.tev = golden, tev          # against.Golden, tev.Tev (or None)
        self.frame = options.frame
        self.requests: queue.Queue = queue.Queue(PENDING)
        self.render = 0                              # the number of the render in hand
        self.scene = self.base = None                # scene_api.Scene of the frame shown, and of frame 1
        self.image = self.ids = None
        self.info = self.error = self.progress = self.done = self.compare = None
        self.warnings: list[str] = []                # the scene's warnings, as `rtcli render` prints them
        self.views: dict = {}                        # a render's debug views, by kind, as they are asked for
        self._kept, self._changes, self._next_poll = None, None, 0.0
        self._reload, self._rerender, self._stopping = True, False, threading.Event()

    # --- what the server calls, from its thread ---

    def ask(self, what: str, *args) -> concurrent.futures.Future:
        """A question for the thread (explain, view, frame), answered between two tiles."""
        future = concurrent.futures.Future()
        try:
            self.requests.put_nowait((what, args, future))
        except queue.Full:
            raise Busy("busy: too many questions wait; ask again") from None
        return future

    def snapshot(self) -> list:
        """What a page is sent when it arrives: the scene, the picture as it is (first as the
        first pass left it, a few kilobytes, then whole), the id map, how far the render is, its
        error."""
        image, ids = self.image, self.ids
        pictures = [None, None, messages.ids_message(self.render, ids) if ids is not None else None]
        if image is not None:
            b = passes(*image.shape[1::-1])[0]                  # the first pass's grid points keep their colors
            rows, cols = np.arange(0, image.shape[0], b), np.arange(0, image.shape[1], b)
            pictures[:2] = [messages.tile_message(self.render, b, rows, cols, image[::b, ::b]),
                            messages.image_message(self.render, image)]
        out = [self.info, *pictures, self.progress, self.done, self.compare, {"type": "error", "line": self.error}]
        return [m for m in out if m is not None]

    def stop(self) -> None:
        self._stopping.set()

    def _send(self, message) -> None:
        self.version += 1
        self.publish(message)

    # --- the thread ---

    def run(self) -> None:
        self._kept = Kept()
        while not self._stopping.is_set():
            try:
                if self._reload:
                    self._load()
                if self._rerender:
                    self._render()
                else:
                    self._attend(POLL)
            except Exception as e:         # noqa: BLE001 -- a bug: said on the page, and the next save tries again
                self._rerender = False
                self._failed(RtcliError(f"rtcli preview failed ({type(e).__name__}: {e}); this is a bug in rtcli"))

    def _load(self) -> None:
        """Load the scene file, recording what it reads; publish the error of a broken one."""
        self._reload = False
        o = self.options
        with recording(self.path, self._kept) as seen:
            try:
                loaded = load_file(self.path, None, lint=True)
                base = of_loaded(loaded, self.path).override(o.width, o.height, o.samples, o.max_depth)
                if self.frame > base.frames:
                    self.say(f"note: frame {self.frame}: {shown(self.path)} has {plural(base.frames, 'frame')}; "
                             f"showing frame {base.frames}")
                    self.frame = base.frames
                scene = base.at(self.frame)
            except (RtcliError, MemoryError) as e:
                self._failed(e)
                scene = None
        self._changes = Changes(seen)
        if scene is not None:
            self.base, self.scene, self._rerender = base, scene, True
            self.warnings = lines(loaded.warnings, self.path, base.frames)
            for line in self.warnings:
                self.say(line)

    def _note(self, text: str) -> None:
        """A note of the engine's (that it compiles, once, and how long it took), on stderr and the pages."""
        self.say(f"note: {text}")
        self._send({"type": "note", "line": f"note: {text}"})

    def _failed(self, e: BaseException) -> None:
        self.error = error_line(e)
        self.say(self.error)
        self._send({"type": "error", "line": self.error})

    def _render(self) -> None:
        """Render the scene in hand pass by pass; return early when a file changes, another frame
        is asked for, or the preview stops."""
        self._rerender, o, scene = False, self.options, self.scene
        self.render += 1
        self.views, self.done, self.compare, self.progress = {}, None, None, None
        job = Job(scene.width, scene.height, gamma=o.gamma, engine=o.engine, bvh=o.bvh)
        try:
            run = Progressive(scene.model, job, self._note, o.workers or os.cpu_count() or 1)
        except (RtcliError, MemoryError) as e:
            return self._failed(e)
        self.info = self._scene_info(scene)
        self._send(self.info)
        if self.tev is not None:
            self.tev.begin(self._title(), scene.width, scene.height)
        try:
            with contextlib.closing(run.tiles()) as tiles:     # closed: the tiles in flight are waited for
                for tile in tiles:
                    self._show(run, tile)
                    if tile.last and tile.block == run.blocks[0]:
                        self.image = run.image        # a page arriving now sees the first pass, not black
                        self._signature()
                    if self._interrupted():
                        return
        except (RtcliError, MemoryError) as e:
            return self._failed(e)
        self._finish(run)

    def _interrupted(self) -> bool:
        """Answer the questions waiting; whether the render in hand is to stop."""
        self._attend(0)
        return self._reload or self._rerender or self._stopping.is_set()

    def _show(self, run: Progressive, tile) -> None:
        if self.error is not None:
            self.error = None
            self._send({"type": "error", "line": None})
        self._send(messages.tile_message(self.render, tile.block, tile.rows, tile.cols, tile.pixels))
        p = run.progress
        self.progress = {"type": "progress", "render": self.render, "block": tile.block, "last": tile.last,
                         "traced": p.traced, "pixels": p.pixels, "seconds": p.seconds, "eta": p.eta}
        self._send(self.progress)
        if self.tev is not None:
            self.tev.tile(tile)

    def _signature(self) -> None:
        """The id map of the scene in hand (hover and outline on the page), when its ids fit in 16 bits."""
        if len(self.scene.model.objects) > MAX_IDS:
            return
        self.ids = np.asarray(signature(self.scene, workers=1))
        self._send(messages.ids_message(self.render, self.ids))

    def _finish(self, run: Progressive) -> None:
        """The render is done: its stats, the golden comparison, tev's channels."""
        s, scene = run.stats, self.scene
        stats = RenderStats.of(scene.width, scene.height, scene.model.settings.samples, s, run.progress.seconds,
                               start_up=False)
        self.done = {"type": "done", "render": self.render, "seconds": run.progress.seconds, "stats": stats.line()}
        self._send(self.done)
        self.say(f"rendered {self._title()} ({scene.width}x{scene.height}) in {run.progress.seconds:.2f} s")
        if self.golden is not None:
            self.compare = self.golden.compare(self.render, self.image)
            self._send(self.compare)
        if self.tev is not None:
            self.tev.image(run.linear)
            for kind in VIEWS:
                if self._interrupted():
                    return
                self.tev.view(kind, self._view(kind)[0])

    def _title(self) -> str:
        name = os.path.basename(self.path)
        return name if self.base.frames == 1 else f"{name} frame {self.frame}"

    def _scene_info(self, scene) -> dict:
        return {"type": "scene", "render": self.render, "name": shown(self.path), "title": self._title(),
                "width": scene.width, "height": scene.height, "frame": self.frame, "frames": self.base.frames,
                "samples": scene.model.settings.samples, "warnings": self.warnings,
                "against": self.golden.about() if self.golden is not None else None,
                "objects": [{"id": r.id, "name": one_line(r.name), "shape": r.shape, "material": one_line(r.material)}
                            for r in object_rows(scene.model)] if len(scene.model.objects) <= MAX_IDS else []}

    # --- questions, and the watch, between two tiles ---

    def _attend(self, timeout: float) -> None:
        """Answer the questions waiting (waiting up to `timeout` for one), and look at the files
        when a poll is due."""
        try:
            self._answer(*(self.requests.get(timeout=timeout) if timeout else self.requests.get_nowait()))
            while True:
                self._answer(*self.requests.get_nowait())
        except queue.Empty:
            pass
        now = time.monotonic()
        if self._changes is not None and now >= self._next_poll:
            self._next_poll = now + POLL
            if self._changes.poll():
                self._reload = True

    def _answer(self, what: str, args: tuple, future: concurrent.futures.Future) -> None:
        if not future.set_running_or_notify_cancel():
            return
        answer = {"explain": self._explain, "view": self._view, "frame": self._frame}[what]
        try:
            future.set_result(answer(*args))
        except (RtcliError, MemoryError) as e:
            future.set_exception(RtcliError(one_line(str(e) or "out of memory")))
        except Exception as e:             # noqa: BLE001 -- a bug: the page says so, and the preview goes on
            future.set_exception(RtcliError(f"{type(e).__name__}: {e} (a bug in rtcli)"))

    def _explain(self, x: int, y: int) -> tuple[str, str]:
        """Pixel (x, y) of the frame shown explained: `rtcli explain --json`'s text, and its tree as
        `rtcli explain` prints it (rtcli/inspect/explain.py)."""
        if self.scene is None:
            raise RtcliError("the scene has not loaded: nothing to explain")
        e = explain(self.scene, x, y, gamma=self.options.gamma, bvh=self.options.bvh)
        return e.json(), e.text(0)

    def _view(self, kind: str) -> tuple[np.ndarray, str, bytes]:
        """(data, summary, PNG) of the debug view `kind` of the frame shown (rtcli/inspect/views.py)."""
        if self.scene is None:
            raise RtcliError("the scene has not loaded: no view to show")
        if kind not in VIEWS:
            raise RtcliError(f"the view must be one of {', '.join(VIEWS)}, got {one_line(kind)!r}")
        if kind not in self.views:
            max_depth = self.scene.model.settings.max_depth
            data = self.ids if kind == "ids" and self.ids is not None else np.asarray(view(self.scene, kind))
            self.views[kind] = (data, summary(data, kind, max_depth), png_bytes(picture(data, kind, max_depth)))
        return self.views[kind]

    def _frame(self, k: int) -> int:
        """Show frame k (a page's frame slider); the frame shown."""
        if self.base is None:
            raise RtcliError("the scene has not loaded: no frame to show")
        if k != self.frame:
            self.scene, self.frame, self._rerender = self.base.at(k), k, True       # at(): an error for a bad k
        return self.frame
