"""Features against POV-Ray 3.7: each scene of tests/data/povray/features/ (NAME.yaml) beside its
POV-Ray twin (NAME.pov) — smooth OBJ meshes, textured csg children, spot, colored attenuated and
area lights, checker and image textures, a torus, cones and cylinders under non-uniform transforms.

POV-Ray renders the .pov afresh; without it (`apt-get install povray`) the tests skip. A mesh
reaches POV-Ray as a mesh2 the test writes from rtcli's own mesh (its corners, corner normals and
(u, v)), so both trace the same triangles. The two images must agree to within 8/255 in every
channel away from edges: pixels within two of another object in rtcli's signature, or where
rtcli's image changes by more than 24/255 within a pixel (checker and shadow boundaries, the
picture's lines), are left out. Only rtcli's edges are left out: an edge POV-Ray has where rtcli
has none (a checker cell shifted) is a difference.
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
from rtcli.shapes.mesh import Mesh
from rtcli.shapes.triangle import E1, E2, NA, UVA, A

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data" / "povray" / "features"
W, H = 160, 120
TOLERANCE, EDGE = 8, 24
SCENES = sorted(p.stem for p in DATA.glob("*.yaml"))
pytestmark = pytest.mark.skipif(shutil.which("povray") is None,
                                reason="POV-Ray is not installed (apt-get install povray)")


def vectors(rows) -> str:
    return ", ".join("<" + ", ".join(format(float(x), ".17g") for x in row) + ">" for row in rows)


def mesh2(mesh: Mesh) -> str:
    """The mesh as POV-Ray's mesh2, corner by corner: rtcli's corners, corner normals when smooth,
    corner (u, v) when it has them."""
    pool = mesh.pool
    corners = np.stack([pool[:, A:A + 3], pool[:, A:A + 3] + pool[:, E1:E1 + 3], pool[:, A:A + 3] + pool[:, E2:E2 + 3]],
                       axis=1).reshape(-1, 3)
    n = len(corners)
    parts = [f"vertex_vectors {{ {n}, {vectors(corners)} }}"]
    if mesh.smooth:
        parts.append(f"normal_vectors {{ {n}, {vectors(pool[:, NA:NA + 9].reshape(-1, 3))} }}")
    if mesh.row[2]:
        parts.append(f"uv_vectors {{ {n}, {vectors(pool[:, UVA:UVA + 6].reshape(-1, 2))} }}")
    parts.append(f"face_indices {{ {len(pool)}, {vectors(np.arange(n).reshape(-1, 3))} }}")
    return "mesh2 { " + "\n".join(parts) + " }"


def povray_image(name: str, scene, tmp_path: Path) -> np.ndarray:
    meshes = [o.shape for o in scene.objects if isinstance(o.shape, Mesh)]
    (tmp_path / "meshes.inc").write_text("".join(f"#declare Mesh{k + 1} = {mesh2(m)}\n"
                                                 for k, m in enumerate(meshes)))
    out = tmp_path / f"{name}.png"
    subprocess.run(["povray", f"+I{DATA / name}.pov", f"+O{out}", f"+W{W}", f"+H{H}", "-D", "-A", "File_Gamma=1.0",
                    "-V", "-GA", f"+L{DATA}", f"+L{tmp_path}", f"+L{ROOT / 'scenes' / 'models'}",
                    f"+L{ROOT / 'scenes' / 'textures'}"], cwd=tmp_path, check=True, capture_output=True, timeout=600)
    return np.asarray(Image.open(out).convert("RGB"), dtype=int)


def edges(ids, image) -> np.ndarray:
    """Pixels near another object in `ids` (within two pixels), or where rtcli's image changes by
    more than EDGE within the pixel's 3 x 3 neighbourhood (checker and shadow boundaries, the
    picture's lines: a sample a fraction of a pixel away lands on the other side there)."""
    near = ndimage.binary_dilation(ndimage.maximum_filter(ids, size=3) != ndimage.minimum_filter(ids, size=3))
    spread = ndimage.maximum_filter(image, size=(3, 3, 1)) - ndimage.minimum_filter(image, size=(3, 3, 1))
    return near | (spread.max(axis=2) > EDGE)


def compare(name: str, tmp_path: Path, text: str | None = None):
    """(largest difference away from edges, share of pixels compared, where it is largest)."""
    path = DATA / f"{name}.yaml"
    if text is not None:                                # its files named from the repository's root
        path = tmp_path / f"edited_{name}.yaml"
        path.write_text(text.replace("../../../../", f"{ROOT}/"))
    scene = load_scene(str(path))
    image = render(scene, Job(W, H, engine="numpy"))[0].astype(int)
    ids = render(scene, Job(W, H, signature=True))[0]
    pov = povray_image(name, scene, tmp_path)
    Image.fromarray(image.astype(np.uint8)).save(tmp_path / f"{name}.rtcli.png")
    inside = ~edges(ids, image)
    d = np.abs(image - pov).max(axis=2)
    d[~inside] = 0
    worst = np.unravel_index(np.argmax(d), d.shape)
    return d.max(), inside.mean(), worst


@pytest.mark.parametrize("name", SCENES)
def test_rtcli_agrees_with_povray(name, tmp_path):
    worst, share, where = compare(name, tmp_path)
    assert share > 0.5, f"{name}: only {share:.0%} of the pixels are away from edges"
    assert worst <= TOLERANCE, f"{name}: {worst}/255 at pixel (row, column) {where}; images in {tmp_path}"


# scene: (its YAML, edited to what POV-Ray's twin does not do: the terminator's offset, a checker's
# colors swapped (its cells' parity), no attenuation)
APART = {
    "mesh_grazing": ("shadow_terminator: none", "shadow_terminator: offset"),
    "csg_checker": ("colors: [[0.95, 0.8, 0.3], [0.6, 0.15, 0.1]]", "colors: [[0.6, 0.15, 0.1], [0.95, 0.8, 0.3]]"),
    "attenuated": ("attenuation: [0.5, 0, 0.02]", "attenuation: [1, 0, 0]"),
}


@pytest.mark.parametrize("name", APART)
def test_the_comparison_tells_another_model_apart(name, tmp_path):
    """The edited scene no longer agrees: the comparison can fail."""
    same, other = APART[name]
    text = (DATA / f"{name}.yaml").read_text()
    assert same in text
    worst, _, _ = compare(name, tmp_path, text.replace(same, other))
    assert worst > TOLERANCE
