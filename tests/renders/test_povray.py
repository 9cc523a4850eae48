"""Glass against POV-Ray 3.7: each option of the glass model beside its POV-Ray twin
(tests/data/povray/: NAME.yaml and NAME.pov, and POV-Ray's image NAME.png).

POV-Ray renders the .pov afresh when it is installed (`apt-get install povray`); otherwise the
stored image stands in. The two must agree away from silhouettes (pixels next to another
object in rtcli's signature are left out: sampling differs there): a mean difference under 2/255
and under 1% of pixels off by more than 25/255. Each pair also renders with the option turned
to something POV-Ray does not do, to show the comparison can tell. The other features (meshes,
csg, lights, textures, quadrics) are compared in test_povray_features.py.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from scipy import ndimage

from rtcli.rendering.tiles import Job, render
from rtcli.scenefile.load import load_scene

DATA = Path(__file__).resolve().parents[1] / "data" / "povray"
W, H = 160, 120
POVRAY = shutil.which("povray") is not None
# option: (scene, a YAML edit that makes rtcli differ from POV-Ray)
PAIRS = {
    "tir": ("total_internal_reflection: reflect", "total_internal_reflection: drop"),
    "filter": ("shadow: filter", "shadow: true"),
    "nested": ("ior: 1.0, shadow: false", "ior: 1.5, shadow: false"),
    "fresnel": ("fresnel: true", "fresnel: false"),
}


def povray_image(name: str, tmp_path) -> np.ndarray:
    if POVRAY:
        out = tmp_path / f"{name}.png"
        subprocess.run(["povray", f"+I{name}.pov", f"+O{out}", f"+W{W}", f"+H{H}", "-D", "-A", "File_Gamma=1.0",
                        "-V", "-GA"], cwd=DATA, check=True, capture_output=True)
    else:
        out = DATA / f"{name}.png"
    return np.asarray(Image.open(out).convert("RGB"), dtype=int)


def rtcli_image(path: Path):
    scene = load_scene(str(path))
    image, _ = render(scene, Job(W, H, engine="numpy"))
    ids, _ = render(scene, Job(W, H, signature=True))
    return image.astype(int), ids


def difference(a, b, ids):
    """(mean difference, share of pixels off by > 25) away from the edges of ids."""
    edges = ndimage.maximum_filter(ids, size=3) != ndimage.minimum_filter(ids, size=3)
    inside = ~ndimage.binary_dilation(edges)
    d = np.abs(a - b).max(axis=2)[inside]
    return d.mean(), (d > 25).mean()


@pytest.mark.parametrize("name", PAIRS)
def test_rtcli_agrees_with_povray(name, tmp_path):
    pov = povray_image(name, tmp_path)
    image, ids = rtcli_image(DATA / f"{name}.yaml")
    mean, off = difference(image, pov, ids)
    assert mean < 2 and off < 0.01, f"{name}: mean difference {mean:.2f}/255, {off:.2%} of pixels off by > 25"


@pytest.mark.parametrize("name", PAIRS)
def test_the_comparison_tells_another_model_apart(name, tmp_path):
    """The same scene with the option changed (the notes' drop at total internal reflection, a full
    shadow, a bubble of glass, no Fresnel) no longer agrees with POV-Ray."""
    same, other = PAIRS[name]
    text = (DATA / f"{name}.yaml").read_text()
    assert same in text
    shutil.copy(DATA / "_common.yaml", tmp_path)
    (tmp_path / f"{name}.yaml").write_text(text.replace(same, other))
    image, ids = rtcli_image(tmp_path / f"{name}.yaml")
    mean, off = difference(image, povray_image(name, tmp_path), ids)
    assert mean > 2 or off > 0.01
