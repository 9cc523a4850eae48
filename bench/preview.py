"""How soon `rtcli preview` shows a picture: after the page loads, and after a save.

Runs `rtcli preview` on a copy of scenes/whitted.yaml (640x480) and opens its page in Debian's
headless chromium (Playwright pointed at /usr/bin/chromium). The page records when it has drawn
a whole picture (window.rtcliPreview.marks: the render, the pass's block, ms since the page
began loading, and the wall clock). Measured:

- first picture: from the start of the page's loading to its first whole picture;
- after a save: from the scene file's replacement (os.replace, as editors save) to the first
  whole coarse picture (the 16 x 16 pass) of the new render, and to the finished render.

The engine is warm (run `rtcli warmup` first): the preview process is started and has rendered
once before the page opens, as when a user opens the printed URL. The median and the worst of
--saves saves are printed. `--shots DIR` also saves the screenshots of docs/preview.md there.

    python bench/preview.py [--saves 20] [--shots docs/images]
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]


def start(folder: str, *options: str) -> tuple[subprocess.Popen, str]:
    proc = subprocess.Popen([sys.executable, "-m", "rtcli", "preview", "whitted.yaml", "--no-browser", *options],
                            cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            start_new_session=True)
    return proc, proc.stdout.readline().strip()


def stop(proc: subprocess.Popen) -> None:
    os.killpg(proc.pid, signal.SIGINT)
    proc.wait(timeout=30)


def wait_done(page, render: int) -> None:
    page.wait_for_function(f"() => document.body.dataset.state === 'done' && "
                           f"Number(document.body.dataset.render) >= {render}", timeout=120_000)


def marks(page) -> list[dict]:
    return page.evaluate("() => window.rtcliPreview.marks")


def measure(page, url: str, scene: str, saves: int) -> None:
    loads = []
    for _ in range(loads_count := 10):
        page.goto(url)
        wait_done(page, 1)
        loads.append(marks(page)[0]["at"])
    print(f"first picture after the page began loading: {loads[0]:.0f} ms in a browser just started, then "
          f"median {statistics.median(loads[1:]):.0f} ms, worst {max(loads[1:]):.0f} ms ({loads_count - 1} loads)")
    text, coarse, whole = open(scene).read(), [], []
    for k in range(saves):
        render = int(page.get_attribute("body", "data-render"))
        edited = text.replace("[0.75, 0.75, 0.75]", f"[0.75, 0.75, {0.5 + 0.01 * k:.2f}]")
        with open(scene + ".new", "w") as f:
            f.write(edited)
        saved = time.time() * 1000
        os.replace(scene + ".new", scene)
        wait_done(page, render + 1)
        new = [m for m in marks(page) if m["render"] > render]
        coarse.append(new[0]["wall"] - saved)
        whole.append(new[-1]["wall"] - saved)
        assert new[0]["block"] == 16, new
        time.sleep(0.3)
    for name, values in (("first coarse picture after a save", coarse), ("finished render after a save", whole)):
        print(f"{name}: median {statistics.median(values):.0f} ms, worst {max(values):.0f} ms ({saves} saves)")


def shoot(p, folder: str, shots: str) -> None:
    """The screenshots of docs/preview.md."""
    scene = os.path.join(folder, "whitted.yaml")
    text = open(scene).read()
    context = p.chromium.launch_persistent_context(tempfile.mkdtemp(), executable_path=CHROMIUM, headless=True,
                                                   args=FLAGS, viewport={"width": 1360, "height": 820})
    page = context.pages[0]
    proc, url = start(folder)
    try:
        page.goto(url)
        wait_done(page, 1)
        box = page.locator("#overlay").bounding_box()
        page.mouse.click(box["x"] + 430 * box["width"] / 640, box["y"] + 300 * box["height"] / 480)
        page.wait_for_selector("#tree [data-path]")
        page.mouse.move(box["x"] + 450 * box["width"] / 640, box["y"] + 300 * box["height"] / 480)
        page.screenshot(path=os.path.join(shots, "preview-explain.png"))
        page.click("[data-view=bounces]")
        page.wait_for_function("() => document.getElementById('summary').textContent.startsWith('bounces')")
        page.wait_for_function("() => document.getElementById('picture').complete")
        page.screenshot(path=os.path.join(shots, "preview-bounces.png"))
        page.click("[data-view=image]")
        with open(scene, "w") as f:
            f.write(text.replace("radius: 1.0}, material: glass", "raduis: 1.0}, material: glass"))
        page.wait_for_selector("#error:not([hidden])")
        page.screenshot(path=os.path.join(shots, "preview-error.png"))
    finally:
        stop(proc)
        with open(scene, "w") as f:
            f.write(text)
    golden = os.path.relpath(os.path.join(ROOT, "golden_images", "whitted.png"), folder)
    with open(scene, "w") as f:                                   # a glass of another index against the golden
        f.write(text.replace("ior: 1.5", "ior: 1.33"))
    proc, url = start(folder, "--against", golden)
    try:
        page.goto(url)
        page.wait_for_function("() => window.rtcliPreview.comparison !== undefined", timeout=120_000)
        page.click("[data-view=slider]")
        page.fill("#split", "45")
        page.dispatch_event("#split", "input")
        page.wait_for_function("() => document.getElementById('golden').complete")
        page.screenshot(path=os.path.join(shots, "preview-golden.png"))
    finally:
        stop(proc)
        with open(scene, "w") as f:
            f.write(text)
    proc, url = start(folder, "--samples", "4", "--engine", "numpy")          # slow enough to be seen mid-way
    try:
        page.goto(url)
        page.wait_for_function("() => document.body.dataset.block === '4'", timeout=120_000)
        time.sleep(1)                                                # some tiles of the pass in
        page.screenshot(path=os.path.join(shots, "preview-coarse.png"))
    finally:
        stop(proc)
    context.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--saves", type=int, default=20)
    parser.add_argument("--shots", metavar="DIR", help="also save the screenshots of docs/preview.md there")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright
    folder = tempfile.mkdtemp(prefix="rtcli-preview-bench-")
    shutil.copy(os.path.join(ROOT, "scenes", "whitted.yaml"), folder)
    scene = os.path.join(folder, "whitted.yaml")
    with sync_playwright() as p:
        proc, url = start(folder)
        try:
            time.sleep(2)                                          # rendered once: the engine is loaded
            context = p.chromium.launch_persistent_context(tempfile.mkdtemp(), executable_path=CHROMIUM,
                                                           headless=True, args=FLAGS)
            measure(context.pages[0], url, scene, args.saves)
            context.close()
        finally:
            stop(proc)
        if args.shots:
            shoot(p, folder, args.shots)
    shutil.rmtree(folder)


if __name__ == "__main__":
    main()
