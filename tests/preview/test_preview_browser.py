"""`rtcli preview` in a real browser: Debian's chromium, driven by Playwright (which downloads no
browser: it is pointed at /usr/bin/chromium). One page session goes through what a user does:
the picture, hover, a click and its ray tree, the views, the golden comparison, the frame
slider, a save, a broken save and its fix; and a request without the token is refused.

Skipped without chromium or Playwright (.ci/run installs chromium; `make test` Playwright).
Only loopback addresses; no assertion is about time.
"""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image
from preview_helpers import DEADLINE, GREEN, LOOK, Preview, save, write_scene

import rtcli
from rtcli.cli import main
from rtcli.inspect import views
from rtcli.preview.against import flip_installed

CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]

pytestmark = pytest.mark.skipif(not os.path.exists(CHROMIUM), reason="needs Debian's chromium (.ci/run installs it)")
playwright = pytest.importorskip("playwright.sync_api", reason="needs Playwright (the test extra)")


@pytest.fixture
def browser(tmp_path):
    """A page in a headless chromium with a new, empty profile."""
    with playwright.sync_playwright() as p:
        context = p.chromium.launch_persistent_context(tmp_path / "profile", executable_path=CHROMIUM, headless=True,
                                                       args=FLAGS, viewport={"width": 1280, "height": 900})
        page = context.pages[0] if context.pages else context.new_page()
        errors = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.set_default_timeout(DEADLINE * 1000)
        yield page
        context.close()
        assert not errors, errors


def canvas(page) -> np.ndarray:
    """The picture on the page's canvas, RGB."""
    data = page.evaluate("""() => { const c = document.getElementById('image');
        return [c.width, c.height, Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data)]; }""")
    w, h, rgba = data
    return np.array(rgba, np.uint8).reshape(h, w, 4)[..., :3]


def wait_done(page, render: int) -> None:
    """Wait until render number `render` (or a later one) is done on the page."""
    page.wait_for_function(f"() => document.body.dataset.state === 'done' && "
                           f"Number(document.body.dataset.render) >= {render}")


def point(page, x: int, y: int) -> dict:
    """Where pixel (x, y)'s centre is on the screen."""
    box = page.locator("#overlay").bounding_box()
    return {"x": box["x"] + (x + 0.5) * box["width"] / 96, "y": box["y"] + (y + 0.5) * box["height"] / 72}


def numbers(tree, path: str = ""):
    """(path, value) of every number and vector of numbers in explain's JSON."""
    if isinstance(tree, dict):
        for k, v in tree.items():
            yield from numbers(v, f"{path}.{k}" if path else k)
    elif isinstance(tree, list) and tree and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                  for v in tree):
        yield path, tree
    elif isinstance(tree, list):
        for i, v in enumerate(tree):
            yield from numbers(v, f"{path}.{i}")
    elif isinstance(tree, (int, float)) and not isinstance(tree, bool):
        yield path, tree


def test_a_user_s_session_in_the_browser(tmp_path, browser, monkeypatch):
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    path = write_scene(work).relative_to(work)
    scene = rtcli.load_scene(path)
    Image.fromarray(np.asarray(rtcli.render(scene, frame=3))).save(tmp_path / "golden.png")
    preview = Preview(work, "--against", str(tmp_path / "golden.png"))
    page = browser
    try:
        assert page.goto(preview.base).status == 401                     # no token: refused
        assert page.goto(preview.base + "?token=guess").status == 403
        page.goto(preview.url)
        wait_done(page, 1)
        np.testing.assert_array_equal(canvas(page), rtcli.render(scene))
        assert page.title() == "scene.yaml frame 1 · rtcli preview"

        # hover: the object under the cursor, from the id map
        ids = np.asarray(rtcli.signature(scene))
        y, x = (int(v) for v in np.argwhere(ids == 2)[len(np.argwhere(ids == 2)) // 2])
        page.wait_for_function("() => window.rtcliPreview.ids !== null")
        page.mouse.move(**point(page, x, y))
        assert f"({x}, {y}) #2 ball · sphere · material paint" in page.inner_text("#hover")

        # a click: explain's numbers, each where its JSON path says; the object outlined
        page.mouse.click(**point(page, x, y))
        page.wait_for_selector("#tree [data-path]")
        shown = dict(page.eval_on_selector_all("[data-path]", "es => es.map(e => [e.dataset.path, e.dataset.value])"))
        explained = json.loads(CliRunner().invoke(main, ["explain", str(path), str(x), str(y), "--json"]).output)
        expected = dict(numbers({k: v for k, v in explained.items() if k != "samples"}))
        expected.update(numbers(explained["samples"][0], "samples.0"))
        assert len(expected) > 60 and any(".children.0." in p for p in expected)   # a tree with a reflected ray
        for where, value in expected.items():
            assert where in shown, f"{where} is not on the page"
            assert json.loads(shown[where]) == value, where
        head = page.inner_text("#explain-head")
        assert head.startswith(f"pixel ({x}, {y}) of (96, 72) = ")
        assert page.get_attribute("body", "data-outlined") == "2"
        outline = page.evaluate("""() => { const o = document.getElementById('overlay');
            const d = o.getContext('2d').getImageData(0, 0, o.width, o.height).data; let n = 0;
            for (let i = 0; i < d.length; i += 4) n += d[i] === 0 && d[i + 1] === 229 && d[i + 2] === 255;
            return n; }""")
        edge = (ids == 2) & ~(np.pad(ids == 2, 1)[:-2, 1:-1] & np.pad(ids == 2, 1)[2:, 1:-1]
                             & np.pad(ids == 2, 1)[1:-1, :-2] & np.pad(ids == 2, 1)[1:-1, 2:])
        assert outline == int(edge.sum()) - 1 or outline == int(edge.sum())    # less the clicked pixel's cross
        assert page.text_content("#text").startswith(f"pixel ({x}, {y}) of 96x72 = ")

        # the views: each the picture and summary of rtcli.view
        for kind in ("normal", "bounces"):
            page.click(f"[data-view={kind}]")
            data = np.asarray(rtcli.view(scene, kind))
            page.wait_for_function(f"() => document.getElementById('summary').textContent === "
                                   f"{json.dumps(views.summary(data, kind, 5))}")
            page.wait_for_function("() => { const p = document.getElementById('picture'); "
                                   "return !p.hidden && p.complete && p.naturalWidth === 96; }")
        page.click("[data-view=image]")
        assert page.is_hidden("#picture")

        # the golden image: the comparison's line, its heat map, the slider
        d = rtcli.diff(rtcli.render(scene), tmp_path / "golden.png", flip=flip_installed())
        page.click("[data-view=diff]")
        page.wait_for_function("() => document.getElementById('picture').complete")
        assert page.inner_text("#summary") == f"golden: {d.summary}"
        assert "against/diff.png" in page.get_attribute("#picture", "src")
        page.click("[data-view=slider]")
        page.fill("#split", "30")
        page.dispatch_event("#split", "input")
        page.wait_for_selector("#golden", state="visible")          # an image has a size once it has loaded
        assert page.evaluate("() => document.getElementById('golden').style.clipPath") == "inset(0px 0px 0px 30%)"
        page.click("[data-view=image]")

        # the frame slider: frame 2 on demand
        page.fill("#frame", "2")
        page.dispatch_event("#frame", "change")
        wait_done(page, 2)
        page.wait_for_function("() => document.title.startsWith('scene.yaml frame 2')")
        np.testing.assert_array_equal(canvas(page), rtcli.render(scene, frame=2))

        # a save renders again; a broken one shows its error and keeps the picture; fixed, it renders
        save(work / "look.yaml", LOOK % GREEN)
        wait_done(page, 3)
        good = rtcli.render(rtcli.load_scene(path, frame=2))
        np.testing.assert_array_equal(canvas(page), good)
        save(work / path, (work / path).read_text().replace("radius: 1}", "raduis: 1}", 1))
        page.wait_for_selector("#error:not([hidden])")
        with pytest.raises(rtcli.RtcliError) as broken:
            rtcli.load_scene(path)
        assert page.inner_text("#error") == f"error: {broken.value}"
        np.testing.assert_array_equal(canvas(page), good)
        save(work / path, (work / path).read_text().replace("raduis: 1}", "radius: 0.5}"))
        wait_done(page, 4)
        assert page.is_hidden("#error")
        np.testing.assert_array_equal(canvas(page), rtcli.render(rtcli.load_scene(path, frame=2)))
    finally:
        code, _ = preview.stop()
    assert code == 130
