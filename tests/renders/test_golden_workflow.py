"""The golden workflow's guard rails, run as a user would run them."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run_pytest(*args, **env):
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "tests/renders/test_golden.py", *args], cwd=ROOT, capture_output=True, text=True,
                          env={**os.environ, **env})


def test_update_goldens_is_refused_in_ci():
    """`make golden` (pytest --update-goldens) fails, writing nothing, when CI is set."""
    before = (ROOT / "golden_images" / "phong.png").read_bytes()
    done = run_pytest("--update-goldens", "-k", "render and phong", CI="true")
    assert done.returncode != 0
    assert "refusing to update golden images when CI is set" in done.stdout
    assert (ROOT / "golden_images" / "phong.png").read_bytes() == before
