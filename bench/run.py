"""rtcli against POV-Ray 3.7 and Mitsuba 3 on the reference scenes, side by side in one run.

For each scene and size, rtcli, POV-Ray (when `povray` is on PATH) and Mitsuba 3
(when a Python with mitsuba is found: variants llvm_ad_rgb and scalar_rgb, the
scenes of bench/mitsuba_scenes.py) render in turn, `--runs` times each, every run a
whole process timed by wall clock as a user sees it. The table gives the medians,
rtcli's ratio to each (rtcli / peer; below 1 means rtcli is faster) and rtcli's rays
per second. Each rtcli image is
then checked against POV-Ray's with a loose gate, and the share of pixels that
differ by more than 10% in some channel is reported: the pictures should show
the same objects, lights and shadows.

    python bench/run.py [--runs 3] [--sizes 640x480,1920x1080] [--scenes whitted,quadrics] [--engine auto]
                        [--mitsuba-python PATH] [--mitsuba-variants llvm_ad_rgb,scalar_rgb]

The engine column says which engine rtcli used (`--engine auto` picks numpy for
the small size and the compiled integrator for the large one).

The big scenes, `--scenes million,torus1m` (a million spheres, a million triangles), are
generated once into bench/.cache by bench/big_scenes.py (the same bytes each time) and
rendered at 640x480 only; rtcli runs them through bench/phases.py, and a second line gives
rtcli's phases (start, load, build, trace, write: median seconds) and each program's peak
memory (median MB of its largest process; rtcli's workers are forked after the scene is
built, and share its pages).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from big_scenes import ensure  # noqa: E402  (bench/ is not a package: its folder on the path first)
SCENES = ["whitted", "quadrics", "spheres1k", "torus100k"]
BIG = ["million", "torus1m"]           # generated into bench/.cache (bench/big_scenes.py), 640x480 only


def timed(cmd: list[str], cwd: str) -> tuple[float, str]:
    seconds, stdout, _ = measured(cmd, cwd)
    return seconds, stdout


def measured(cmd: list[str], cwd: str) -> tuple[float, str, float]:
    """(wall seconds, stdout, peak resident MB of the process itself: ru_maxrss from wait4)."""
    start = time.perf_counter()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        p = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        seconds = time.perf_counter() - start
        p.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        stdout, stderr = out.read().decode(), err.read().decode()
    if p.returncode != 0:
        raise Failed(f"failed ({p.returncode}): {' '.join(cmd)}\n{stderr[-2000:]}")
    return seconds, stdout, usage.ru_maxrss / 1024


class Failed(RuntimeError):
    """A program of the bench exited with an error: rtcli's ends the bench, a peer's its column."""


def rtcli_cmd(scene, out, w, h, workers, engine):
    return [sys.executable, "-m", "rtcli", "render", f"{scene}.yaml", "-o", out, "--width", str(w),
            "--height", str(h), "--quiet", "--stats", "--workers", str(workers), "--engine", engine]


def povray_cmd(scene, out, w, h, workers):
    return ["povray", f"+I{scene}.pov", f"+O{out}", f"+W{w}", f"+H{h}", "-D", "-A",
            f"+WT{workers}", "File_Gamma=1.0", "-V", "-GA"]


def differing_share(a_path: str, b_path: str) -> float:
    a = np.asarray(Image.open(a_path).convert("RGB"), dtype=int)
    b = np.asarray(Image.open(b_path).convert("RGB"), dtype=int)
    if a.shape != b.shape:
        return float("nan")
    return float(np.mean(np.abs(a - b).max(axis=2) > 25))


def phases_cmd(scene, out, w, h, workers, engine):
    """rtcli on a big scene: bench/phases.py, the render timed phase by phase, with peak memory."""
    return [sys.executable, os.path.join(HERE, "phases.py"), f"{scene}.yaml", out, "--width", str(w),
            "--height", str(h), "--workers", str(workers), "--engine", engine]


def framed_like_povray(scene: str, w: int, h: int) -> str:
    """The scene's YAML name, or a copy whose vertical fov gives POV-Ray's framing at w x h.

    POV-Ray's `angle` fixes the horizontal field of view and rtcli's `fov` the
    vertical one; they agree at the scene's own aspect ratio (4:3).
    """
    if scene in BIG:
        return scene                                                  # written for 640x480 only
    text = open(os.path.join(HERE, f"{scene}.yaml")).read()
    match = re.search(r"fov: ([0-9.]+)", text)
    size = re.search(r"image: \{width: (\d+), height: (\d+)\}", text)
    w0, h0 = int(size.group(1)), int(size.group(2))
    if match is None or w * h0 == h * w0:
        return scene
    tan_h = np.tan(np.radians(float(match.group(1))) / 2) * w0 / h0
    fov = np.degrees(2 * np.arctan(tan_h * h / w))
    name = f".{scene}_{w}x{h}"
    with open(os.path.join(HERE, f"{name}.yaml"), "w") as f:
        f.write(text.replace(match.group(0), f"fov: {fov:.4f}"))
    return name


def mitsuba_cmd(python, scene, variant, out, w, h):
    return [python, os.path.join(HERE, "mitsuba_scenes.py"), scene, variant, str(w), str(h), out]


def has_mitsuba(python: str) -> bool:
    return subprocess.run([python, "-c", "import mitsuba"], capture_output=True).returncode == 0


def bench(scene, w, h, runs, workers, engine, tmp, pov, mitsuba):
    """Median whole-process seconds of rtcli and each peer, run in turn `runs` times, and their median
    peak memory (MB); rtcli's rays per second, the engine it used, the share of pixels differing
    from POV-Ray's image, and for a big scene rtcli's median phases (bench/phases.py)."""
    from mitsuba_scenes import SCENES as MITSUBA_SCENES
    folder = ensure() if scene in BIG else HERE
    rt_scene = framed_like_povray(scene, w, h)
    out = lambda who: os.path.join(tmp, f"{scene}_{w}x{h}_{who}.png")        # noqa: E731
    programs = {"rtcli": None}
    if pov:
        programs["POV-Ray"] = povray_cmd(scene, out("pov"), w, h, workers)
    for variant in mitsuba["variants"] if mitsuba and scene in MITSUBA_SCENES else ():
        programs[variant] = mitsuba_cmd(mitsuba["python"], scene, variant, out(variant), w, h)
    times, peaks, phases = {name: [] for name in programs}, {name: [] for name in programs}, []
    rays, used = 0, "?"
    for _ in range(runs):
        for name, cmd in programs.items():
            if name == "rtcli" and scene in BIG:
                seconds, stdout, peak = measured(phases_cmd(rt_scene, out("rt"), w, h, workers, engine), folder)
                report = json.loads(stdout)
                rays, used, peak = report["rays"], report["engine"], max(report["peak_mb"], report["worker_peak_mb"])
                phases.append(report["phases"])
            elif name == "rtcli":
                seconds, stdout, peak = measured(rtcli_cmd(rt_scene, out("rt"), w, h, workers, engine), folder)
                rays = int(re.search(r"(\d+) total", stdout).group(1))
                used = re.search(r"(\w+) engine", stdout).group(1)
            elif name in times:
                try:
                    seconds, _, peak = measured(cmd, folder)
                except Failed as e:                  # say why once; the column shows "failed"
                    lines = str(e).strip().splitlines()
                    why = next((line for line in lines if "ERROR" in line or "Error" in line), lines[-1])
                    print(f"{name} on {scene} {w}x{h}: {why.strip()[:200]}", file=sys.stderr)
                    del times[name], peaks[name]
                    continue
            else:
                continue
            times[name].append(seconds)
            peaks[name].append(peak)
    if rt_scene != scene:
        os.remove(os.path.join(HERE, f"{rt_scene}.yaml"))
    medians = {name: statistics.median(t) for name, t in times.items()}
    memory = {name: statistics.median(m) for name, m in peaks.items()}
    share = differing_share(out("rt"), out("pov")) if pov else float("nan")
    phase = {k: statistics.median(p[k] for p in phases) for k in phases[0]} if phases else {}
    return medians, rays / medians["rtcli"], share, used, memory, phase


def failed(scene: str) -> set:
    """The peers that could render `scene` (mitsuba_scenes' scenes) but failed: not in the medians."""
    from mitsuba_scenes import SCENES as MITSUBA_SCENES
    return {"POV-Ray"} | (set(MITSUBA_VARIANTS) if scene in MITSUBA_SCENES else set())


MITSUBA_VARIANTS: list = []


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--sizes", default="640x480,1920x1080")
    ap.add_argument("--scenes", default=",".join(SCENES),
                    help=f"of {', '.join(SCENES + BIG)} (the big ones are generated once into bench/.cache)")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--engine", default="auto", choices=["auto", "numpy", "compiled"])
    ap.add_argument("--mitsuba-python", default=sys.executable,
                    help="a Python that imports mitsuba (default: this one; the 'bench' extra installs it)")
    ap.add_argument("--mitsuba-variants", default="llvm_ad_rgb,scalar_rgb")
    ap.add_argument("--keep", help="folder to keep the rendered images in")
    args = ap.parse_args()
    pov = shutil.which("povray") is not None
    if not pov:
        print("povray not found (apt-get install povray): no POV-Ray column")
    mitsuba = None
    if has_mitsuba(args.mitsuba_python):
        mitsuba = {"python": args.mitsuba_python, "variants": args.mitsuba_variants.split(",")}
        MITSUBA_VARIANTS[:] = mitsuba["variants"]
    else:
        print("mitsuba not found (pip install -e '.[bench]', or --mitsuba-python): no Mitsuba columns")
    tmp = args.keep or tempfile.mkdtemp(prefix="rtcli-bench-")
    os.makedirs(tmp, exist_ok=True)
    peers = (["POV-Ray"] if pov else []) + (mitsuba["variants"] if mitsuba else [])
    print(f"{'scene':<10} {'size':>9} {'engine':>8} {'rtcli s':>8} "
          + "".join(f"{p + ' s':>15} {'ratio':>6} " for p in peers) + f"{'rtcli rays/s':>13} {'differ':>7}")
    for scene in args.scenes.split(","):
        for size in args.sizes.split(",") if scene not in BIG else ["640x480"]:
            w, h = (int(x) for x in size.split("x"))
            medians, rate, share, used, memory, phase = bench(scene, w, h, args.runs, args.workers, args.engine,
                                                              tmp, pov, mitsuba)
            rt = medians["rtcli"]
            cells = "".join(f"{medians[p]:15.2f} {rt / medians[p]:6.2f} " if p in medians else
                            f"{'failed' if p in failed(scene) else '-':>15} {'-':>6} " for p in peers)
            print(f"{scene:<10} {size:>9} {used:>8} {rt:8.2f} {cells}{rate:13,.0f} {share:7.1%}", flush=True)
            if scene in BIG:
                print(f"{'':<10} rtcli phases (median s): " + ", ".join(f"{k} {v:.2f}" for k, v in phase.items())
                      + "; peak MB (median, the largest process): "
                      + ", ".join(f"{name} {mb:,.0f}" for name, mb in memory.items()), flush=True)
    print(f"ratio: rtcli / peer, below 1 when rtcli is faster. Mitsuba does the same work on "
          f"spheres1k and torus100k, similar work on whitted (a path tracer), none on quadrics. Images in {tmp}")


if __name__ == "__main__":
    main()
