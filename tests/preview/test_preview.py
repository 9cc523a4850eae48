"""`rtcli preview`: the passes, and the server as a real process read through its websocket as a
page reads it (the browser's own tests: test_preview_browser.py). Only loopback addresses; no
assertion is about time."""

from __future__ import annotations

import asyncio
import contextlib
import io
import json
import os
import socket
import struct
import sys
import threading

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image
from preview_helpers import GREEN, LOOK, Page, Preview, read_page, save, write_scene

import rtcli
from rtcli.cli import main
from rtcli.inspect import views
from rtcli.kernels import variants
from rtcli.preview import server
from rtcli.preview.against import flip_installed
from rtcli.preview.passes import Progressive, passes
from rtcli.rendering.tiles import Job
from rtcli.rendering.watch import Changes

aiohttp = pytest.importorskip("aiohttp", reason="rtcli preview needs the extra `preview`")


# --- the passes ---

@pytest.mark.parametrize("samples", [1, 2])
def test_each_pass_is_the_block_size_preview_and_the_last_the_render(tmp_path, samples):
    scene = rtcli.load_scene(write_scene(tmp_path), width=70, samples=samples)       # 70x52: blocks cut at the edges
    run = Progressive(scene.model, Job(scene.width, scene.height, engine="numpy"))
    seen = []
    for tile in run.tiles():
        if tile.last:
            expected = rtcli.render(scene, block_size=tile.block, workers=1, engine="numpy")
            np.testing.assert_array_equal(run.image, expected, err_msg=f"pass {tile.block}")
            seen.append(tile.block)
    assert seen == [16, 8, 4, 2, 1] == passes(70, 52)
    np.testing.assert_array_equal(run.linear, rtcli.render(scene, linear=True, workers=1, engine="numpy"))
    assert run.progress.traced == 70 * 52 and run.stats.primary == 70 * 52 * samples ** 2   # each pixel once


@pytest.mark.skipif(not variants.ENABLED, reason="needs numba (the compiled engine)")
def test_the_compiled_engine_traces_the_tiles_in_threads_to_the_same_bytes(tmp_path):
    scene = rtcli.load_scene(write_scene(tmp_path), width=80, samples=2)
    run = Progressive(scene.model, Job(scene.width, scene.height, engine="compiled"), threads=3)
    tiles = list(run.tiles())
    assert run.threads == 3 and run.stats.engine == "compiled"
    assert [t.block for t in tiles if t.last] == [16, 8, 4, 2, 1]
    np.testing.assert_array_equal(run.image, rtcli.render(scene, engine="numpy", workers=1))
    np.testing.assert_array_equal(run.linear, rtcli.render(scene, linear=True, engine="numpy", workers=1))
    stopped = Progressive(scene.model, Job(scene.width, scene.height, engine="compiled"), threads=3)
    with contextlib.closing(stopped.tiles()) as some:
        for tile in some:
            if tile.block == 4:
                break                                            # a save: the render stops within the pass
    assert 0 < stopped.progress.traced < 80 * 60


def test_a_small_image_has_no_pass_of_blocks_as_big_as_itself():
    assert passes(16, 9) == [8, 4, 2, 1] and passes(1, 1) == [1]


def test_changes_are_taken_once_they_hold_still(tmp_path):
    path = tmp_path / "a.yaml"
    path.write_text("one")
    from rtcli.rendering.watch import recording
    from rtcli.scenefile.reuse import Kept
    with recording(str(path), Kept()) as seen:
        pass
    changes = Changes(seen)
    assert not changes.poll()                            # nothing changed
    path.write_text("two, longer")
    assert not changes.poll()                            # changed: wait one poll for it to hold still
    assert changes.poll()


def test_a_page_that_reads_slowly_is_sent_the_picture_afresh_not_an_endless_queue():
    class Socket:
        closed = False
    page = server.Page(Socket())
    for _ in range(3 * server.PAGE_BYTES // (1 << 20)):
        page.put(b"x" * (1 << 20))
    assert page.size <= server.PAGE_BYTES and page.behind


# --- the server ---

def fake_tev():
    """A tev stand-in on 127.0.0.1: reads tev's packets (CreateImage, UpdateImage, CloseImage) and
    keeps each image's channels; (port, images, thread)."""
    listener = socket.create_server(("127.0.0.1", 0))
    images: dict = {}

    def string(data, at):
        end = data.index(b"\0", at)
        return data[at:end].decode(), end + 1

    def serve():
        conn, _ = listener.accept()
        with conn, conn.makefile("rb") as f:
            while head := f.read(4):
                size = struct.unpack("<I", head)[0]
                body = f.read(size - 4)
                kind = body[0]
                if kind == 4:                                            # CreateImage
                    name, at = string(body, 2)
                    w, h, n = struct.unpack_from("<iii", body, at)
                    at += 12
                    images[name] = {"size": (w, h), "channels": {}}
                    for _ in range(n):
                        channel, at = string(body, at)
                        images[name]["channels"][channel] = np.full((h, w), np.nan, np.float32)
                elif kind == 6:                                          # UpdateImage
                    name, at = string(body, 2)
                    n = struct.unpack_from("<i", body, at)[0]
                    at += 4
                    names = []
                    for _ in range(n):
                        channel, at = string(body, at)
                        names.append(channel)
                    x, y, w, h = struct.unpack_from("<iiii", body, at)
                    at += 16 + 16 * n                                      # offsets and strides
                    data = np.frombuffer(body, "<f4", w * h * n, at).reshape(h, w, n)
                    for k, channel in enumerate(names):
                        images[name]["channels"][channel][y:y + h, x:x + w] = data[..., k]
                elif kind == 2:                                          # CloseImage
                    images.pop(string(body, 1)[0], None)
    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    return listener.getsockname()[1], images, thread


def http(preview: Preview, path: str, token: str | None = "", cookie: str | None = None, **query):
    """(status, headers, body) of a GET of `path` with `query`; token "" means the right one, None none."""
    import urllib.error
    import urllib.request
    from urllib.parse import urlencode
    if token is not None:
        query["token"] = token or preview.token
    url = preview.base + path + ("?" + urlencode(query) if query else "")
    request = urllib.request.Request(url, headers={"Cookie": cookie} if cookie else {})
    try:
        with urllib.request.urlopen(request, timeout=60) as r:
            return r.status, r.headers, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.headers, e.read()


def test_preview_serves_the_render_explains_it_and_streams_it_to_tev(tmp_path):
    work = tmp_path / "work"
    work.mkdir()
    path = write_scene(work)
    scene = rtcli.load_scene(path)
    golden = rtcli.render(rtcli.load_scene(path, frame=3))          # another frame: the comparison fails
    Image.fromarray(np.asarray(golden)).save(tmp_path / "golden.png")
    tev_port, tev_images, _ = fake_tev()
    before = sorted(os.listdir(work))
    preview = Preview(work, "--against", str(tmp_path / "golden.png"), "--tev", f"127.0.0.1:{tev_port}")
    try:
        assert preview.host == "127.0.0.1" and len(preview.token) >= 32

        # every request needs the token: none 401, a wrong one 403; the page's cookie serves its assets
        assert http(preview, "", token=None)[0] == 401
        assert http(preview, "", token="wrong")[0] == 403
        assert http(preview, "static/preview.js", token=None)[0] == 401
        status, headers, body = http(preview, "")
        assert status == 200 and b"preview.js" in body
        assert "frame-ancestors 'none'" in headers["Content-Security-Policy"]
        cookie = headers["Set-Cookie"].split(";")[0]
        assert "HttpOnly" in headers["Set-Cookie"] and "SameSite=Strict" in headers["Set-Cookie"]
        assert http(preview, "static/preview.js", token=None, cookie=cookie)[0] == 200
        for path_asked in ("static/index.html", "static/..%2f__init__.py", "static/%2e%2e%2fserver.py",
                           "../../etc/passwd", "static/preview.js/.."):
            assert http(preview, path_asked)[0] == 404, path_asked

        # a websocket from another origin is refused; the page's own reads the render
        with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
            read_page(preview, lambda p: False, origin="http://evil.example")
        assert refused.value.status == 403
        page = read_page(preview, lambda p: p.done() and p.ids is not None and p.last("compare"),
                         origin=f"http://127.0.0.1:{preview.port}")
        np.testing.assert_array_equal(page.picture, rtcli.render(scene))
        np.testing.assert_array_equal(page.ids, rtcli.signature(scene))
        info = page.last("scene")
        assert (info["width"], info["height"], info["frame"], info["frames"]) == (96, 72, 1, 3)
        assert [(o["id"], o["name"], o["shape"], o["material"]) for o in info["objects"]] == \
            [(1, "floor", "plane", "floor"), (2, "ball", "sphere", "paint"), (3, "glass ball", "sphere", "glass")]
        blocks = [m["block"] for m in page.json if m["type"] == "progress" and m["last"]]
        assert blocks == sorted(blocks, reverse=True) and blocks[-1] == 1      # coarse to fine, from where it is

        # explain: the command line's JSON and text, for the frame shown
        for x, y in ((48, 40), (30, 10), (0, 71)):
            cli = CliRunner().invoke(main, ["explain", str(path), str(x), str(y), "--json"])
            assert json.loads(http(preview, "explain.json", x=x, y=y)[2]) == json.loads(cli.output)
        text = CliRunner().invoke(main, ["explain", str(path), "48", "40"], color=False).output
        assert http(preview, "explain.txt", x=48, y=40)[2].decode() == text
        status, _, body = http(preview, "explain.json", x=96, y=0)
        assert status == 400 and body.decode().startswith("error: pixel (96, 0) is outside the 96x72 image")
        assert http(preview, "explain.json", x="1e9", y=0)[0] == 400

        # the debug views: the picture and the summary rtcli.view gives
        for kind in ("normal", "depth", "ids"):
            data = rtcli.view(scene, kind)
            _, _, png = http(preview, f"view/{kind}.png")
            np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(png)).convert("RGB")),
                                          views.picture(np.asarray(data), kind, 5))
            summary = json.loads(http(preview, f"view/{kind}.json")[2])["summary"]
            assert summary == views.summary(np.asarray(data), kind, 5)
        assert http(preview, "view/shadow.png")[0] == 400

        # --against: the comparison with the golden image, and its heat map
        d = rtcli.diff(rtcli.render(scene), tmp_path / "golden.png", flip=flip_installed())
        assert page.last("compare")["summary"] == d.summary and page.last("compare")["ok"] is False
        heat = http(preview, "against/diff.png")[2]
        np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(heat))), np.asarray(d.heat_map))
        if flip_installed():
            flip = http(preview, "against/flip.png")[2]
            np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(flip))), np.asarray(d.flip_map))
        assert http(preview, "against/nothing.png")[0] == 404

        # --tev: the linear colors as R, G, B, the views as layers
        name = "scene.yaml frame 1"
        preview.wait_for(lambda: name in tev_images and not np.isnan(
            tev_images[name]["channels"]["ids.Y"]).any(), "tev's ids layer")
        channels = tev_images[name]["channels"]
        linear = np.asarray(rtcli.render(scene, linear=True), np.float32)
        np.testing.assert_array_equal(np.dstack([channels[c] for c in "RGB"]), linear)
        depth = np.asarray(rtcli.view(scene, "depth"))
        np.testing.assert_array_equal(channels["depth.Y"], np.where(np.isfinite(depth), depth, 0).astype(np.float32))
        np.testing.assert_array_equal(channels["ids.Y"], np.asarray(rtcli.signature(scene), np.float32))

        # another frame, on demand
        page = read_page(preview, lambda p: any(m["type"] == "done" and m["render"] > 1 for m in p.json),
                         send=[{"frame": 2}])
        assert page.last("scene")["frame"] == 2
        np.testing.assert_array_equal(page.picture, rtcli.render(scene, frame=2))
    finally:
        code, err = preview.stop()
    assert code == 130 and err.splitlines()[-1] == "error: interrupted"
    assert sorted(os.listdir(work)) == before                      # nothing left behind


def test_preview_renders_each_save_and_keeps_the_last_good_picture(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = write_scene(tmp_path).relative_to(tmp_path)
    preview = Preview(tmp_path)
    try:
        page = read_page(preview, lambda p: p.done(1))
        first = page.picture.copy()
        save(tmp_path / "look.yaml", LOOK % GREEN)                      # an included file changes
        read_page(preview, lambda p: p.done(2), page=page)
        np.testing.assert_array_equal(page.picture, rtcli.render(rtcli.load_scene(path)))
        assert not np.array_equal(page.picture, first)
        good = page.picture.copy()

        save(path, path.read_text().replace("radius: 1}", "raduis: 1}", 1))           # a broken edit
        read_page(preview, lambda p: (p.last("error") or {}).get("line"), page=page)
        with pytest.raises(rtcli.RtcliError) as broken:
            rtcli.load_scene(path)
        assert page.last("error")["line"] == f"error: {broken.value}"
        assert "scene.yaml:14:" in page.last("error")["line"]
        later = read_page(preview, lambda p: p.last("error") is not None)     # a page arriving now
        np.testing.assert_array_equal(later.picture, good)          # the last good picture
        assert later.last("error")["line"] == page.last("error")["line"]
        assert f"error: {broken.value}" in preview.stderr()

        save(path, path.read_text().replace("raduis: 1}", "radius: 0.5}"))              # fixed
        read_page(preview, lambda p: p.done(3), page=page)
        assert page.last("error")["line"] is None
        np.testing.assert_array_equal(page.picture, rtcli.render(rtcli.load_scene(path)))
    finally:
        code, _ = preview.stop()
    assert code == 130


def rss(pid: int) -> int:
    with open(f"/proc/{pid}/status") as f:
        return next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmRSS:"))


def raw(preview: Preview, data: bytes, read: bool = True) -> int | None:
    """Send bytes on a new connection; the status the server answers with (None: not read)."""
    with socket.create_connection(("127.0.0.1", preview.port), timeout=60) as s:
        s.sendall(data)
        return int(s.recv(200).split()[1]) if read else None


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc for the memory")
def test_preview_outlives_vanishing_crowded_huge_and_malformed_requests(tmp_path):
    path = write_scene(tmp_path)
    expected = rtcli.render(rtcli.load_scene(path))
    preview = Preview(tmp_path)
    try:
        read_page(preview, lambda p: p.done(1))
        start = rss(preview.proc.pid)
        token = preview.token.encode()
        assert raw(preview, b"GET /?token=" + token + b" HTTP/1.1\r\nHost: a\r\nX-Big: " + b"a" * 100_000 +
                   b"\r\n\r\n") == 400
        assert raw(preview, b"\x00\xff\xfe not http at all\r\n\r\n") == 400
        assert raw(preview, b"POST /?token=" + token + b" HTTP/1.1\r\nHost: a\r\nContent-Length: 100000000\r\n\r\n" +
                   b"x" * 65536) in (405, 413)
        for _ in range(20):                                          # clients that vanish mid-request
            raw(preview, b"GET /ws?token=" + token + b" HTTP/1.1\r\nHost: a\r\nUpgrade: websocket\r\n"
                b"Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                b"Sec-WebSocket-Version: 13\r\n\r\n", read=False)
            raw(preview, b"GET /?tok", read=False)

        async def crowd(n: int):
            url = preview.page("ws").replace("http://", "ws://", 1)
            async with aiohttp.ClientSession() as session:
                sockets = [await session.ws_connect(url) for _ in range(n)]

                async def picture(ws):
                    page = Page()
                    while not page.done():
                        page.take((await ws.receive(timeout=60)).data)
                    return page.picture
                return await asyncio.gather(*(picture(ws) for ws in sockets))
        for picture in asyncio.run(crowd(100)):
            np.testing.assert_array_equal(picture, expected)
        assert http(preview, "")[0] == 200                          # still serving
        np.testing.assert_array_equal(read_page(preview, lambda p: p.done()).picture, expected)
        assert rss(preview.proc.pid) - start < 150 << 20
    finally:
        code, err = preview.stop()
    assert code == 130
    assert [line.split(" ", 1)[1].split(" (")[0] for line in err.splitlines()] == \
        ["rendered scene.yaml frame 1", "interrupted"]                 # no traceback, no line per bad request


# --- the command line's errors ---

def test_a_busy_port_is_one_line(tmp_path):
    write_scene(tmp_path)
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
        result = CliRunner().invoke(main, ["preview", str(tmp_path / "scene.yaml"), "--no-browser", "--port",
                                           str(port)])
    assert result.exit_code == 2
    assert result.output == (f"error: port {port} on 127.0.0.1 is busy: another program listens there; give "
                             "another --port, or --port 0 for any free one\n")


@pytest.mark.parametrize("args, message", [
    (["nowhere.yaml"], "error: nowhere.yaml: no such file\n"),
    (["scene.yaml", "--against", "scene.yaml"], "error: scene.yaml: not a readable PNG"),
    (["scene.yaml", "--tev", "127.0.0.1:1"], "error: --tev 127.0.0.1:1: cannot reach tev there"),
    (["scene.yaml", "--tev", "nowhere:port"], "error: --tev nowhere:port: give HOST:PORT, as 127.0.0.1:14158\n"),
])
def test_bad_options_are_one_line(tmp_path, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    write_scene(tmp_path)
    result = CliRunner().invoke(main, ["preview", *args, "--no-browser"])
    assert result.exit_code == 2 and result.output.startswith(message) and result.output.count("\n") == 1


def test_without_the_extra_it_says_which(tmp_path, monkeypatch):
    write_scene(tmp_path)
    monkeypatch.setitem(sys.modules, "aiohttp", None)
    result = CliRunner().invoke(main, ["preview", str(tmp_path / "scene.yaml"), "--no-browser"])
    assert result.exit_code == 2 and result.output == (
        "error: rtcli preview needs the extra `preview` (aiohttp): pip install -e '.[preview]' in the rtcli folder "
        "(rtcli is not on the package index)\n")


def test_the_browser_is_given_the_url_printed(tmp_path):
    write_scene(tmp_path)
    (tmp_path / "browser.py").write_text("import sys\nopen(sys.argv[0] + '.url', 'w').write(sys.argv[1])\n")
    env = {**os.environ, "BROWSER": f"{sys.executable} {tmp_path / 'browser.py'} %s"}
    preview = Preview(tmp_path, browser=True, env=env)
    try:
        opened = tmp_path / "browser.py.url"
        preview.wait_for(lambda: opened.exists() and opened.read_text(), "the browser")
        assert opened.read_text() == preview.url
    finally:
        assert preview.stop()[0] == 130


def test_another_host_than_127_0_0_1_is_warned_about(tmp_path):
    try:
        socket.create_server(("127.0.0.2", 0)).close()
    except OSError:
        pytest.skip("127.0.0.2 is not a loopback address here")
    write_scene(tmp_path)
    preview = Preview(tmp_path, "--host", "127.0.0.2")
    try:
        assert preview.host == "127.0.0.2"
        warning = "warning: --host 127.0.0.2: the preview is served beyond 127.0.0.1"
        preview.wait_for(lambda: warning in preview.stderr(), "the warning")
        assert http(preview, "")[0] == 200
    finally:
        assert preview.stop()[0] == 130
