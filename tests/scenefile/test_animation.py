"""Animation: the clock, keyframes and their interpolation, each frame's scene, and the errors.

A frame's scene is the still builder's, from the tree with every keyframed value
resolved at the frame's time; the tests check each value that may be animated, that
shapes are shared between frames, and every error by its exact line.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from rtcli.errors import SceneError
from rtcli.scenefile import yamlfile
from rtcli.scenefile.animation import Animation
from rtcli.scenefile.keyframes import EASES
from rtcli.scenefile.load import load_animation, load_scene

SCENE = """\
image: {width: 16, height: 12}
animation: {fps: 4, frames: 8}
camera:
  eye: {keys: {0: [0, 1, 6], 2: [0, 3, 6]}}
  look_at: {keys: {0: [0, 0, 0], 1: [0, 1, 0]}, ease: in_out}
  up: {keys: {0: [0, 1, 0], 2: [1, 1, 0]}}
  fov: {keys: {0.5: 40, 1.5: 60}}
lights:
  - {position: {keys: {0: [5, 5, 5], 2: [-5, 5, 5]}}, color: {keys: {0: "#ff0000", 2: [0, 0, 1]}}}
materials:
  m: {diffuse: {keys: {0: 0.2, 2: [0.8, 0.4, 0.2]}}, shininess: {keys: {0: 10, 2: 50}}, ior: 1.5}
objects:
  - name: ball
    sphere: {}
    material: {reflection: {keys: {0: 0, 2: 0.5}, ease: in}, emission: {keys: {0: [0, 0, 0], 2: [1, 0, 0]}}}
    transform:
      - scale: {keys: {0: 1, 2: [1, 2, 1]}}
      - rotate: {axis: [0, 0, 1], degrees: {keys: {0: 0, 2: 90}, ease: out}}
      - translate: {keys: {0: [0, 0, 0], 2: [4, 0, 0]}}
  - group:
      objects:
        - {box: {}, material: m, transform: [{translate: {keys: {0: [0, 0, 0], 2: [0, 2, 0]}}}]}
"""


@pytest.fixture(autouse=True)
def _in_tmp(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)                # files load by relative name: messages say a.yaml


def animation_of(tmp_path, text: str, name: str = "a.yaml") -> Animation:
    (tmp_path / name).write_text(textwrap.dedent(text))
    return Animation(yamlfile.load(name))


def error_of(tmp_path, text: str, frames=None) -> str:
    with pytest.raises(SceneError) as e:
        a = animation_of(tmp_path, text)
        for k in frames or [1]:
            a.scene(k)
    return str(e.value)


@pytest.fixture
def anim(tmp_path):
    return animation_of(tmp_path, SCENE)


def test_frames_are_at_start_plus_k_over_fps_before_the_end(tmp_path):
    a = animation_of(tmp_path, "animation: {fps: 24, frames: 48}\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n")
    assert (a.frames, a.clock.time(1), a.clock.time(25), a.clock.end) == (48, 0.0, 1.0, 2.0)
    for clock, count in (("[0, 1]", 24), ("[0, 1.01]", 25), ("[2, 3.5]", 36)):
        a = animation_of(tmp_path, f"animation: {{fps: 24, clock: {clock}}}\n"
                                   "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n")
        assert a.frames == count, clock
    assert a.clock.time(1) == 2.0
    still = animation_of(tmp_path, "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n")
    assert (still.still, still.frames) == (True, 1)


def test_every_value_that_may_be_animated_follows_its_keys(anim):
    s0, s3, s5 = anim.scene(1), anim.scene(3), anim.scene(5)              # t = 0, 0.5, 1
    cam = lambda s: s.camera(16, 12)
    np.testing.assert_allclose(cam(s3).eye, [0, 1.5, 6])                   # linear
    np.testing.assert_allclose(s3.lights[0].position, [2.5, 5, 5])
    np.testing.assert_allclose(s3.lights[0].color, [0.75, 0, 0.25])       # "#ff0000" -> [0, 0, 1]
    np.testing.assert_allclose(s3.materials.kd[1], [0.35, 0.25, 0.2])     # 0.2 means [0.2, 0.2, 0.2]
    np.testing.assert_allclose(s3.materials.shininess[1], 20)
    np.testing.assert_allclose(s3.materials.kr[2], 0.25 ** 2 * 0.5)       # ease in: s^2
    np.testing.assert_allclose(s3.materials.emission[2], [0.25, 0, 0])
    np.testing.assert_allclose(s3.objects[1].world_from_object.m[:3, 3], [0, 0.5, 0])     # group child
    ball = s5.objects[0].world_from_object.m                              # t = 1: scale [1, 1.5, 1],
    c, s = np.cos(np.radians(67.5)), np.sin(np.radians(67.5))             # rotated 90 * (1 - 0.5^2)
    np.testing.assert_allclose(ball[:3, :3], [[c, -1.5 * s, 0], [s, 1.5 * c, 0], [0, 0, 1]], atol=1e-12)
    np.testing.assert_allclose(ball[:3, 3], [2, 0, 0])
    assert cam(s0).eye.tolist() == [0, 1, 6] and cam(s5).eye.tolist() == [0, 2, 6]


def test_values_hold_before_the_first_key_and_after_the_last(anim):
    fov = lambda k: np.linalg.norm(anim.scene(k).camera(16, 12).down)    # 2 tan(fov / 2) for a unit focal
    same = lambda k: pytest.approx(fov(k), rel=1e-15)                    # the eye moves: its basis rounds
    assert fov(1) == same(2) == same(3) == pytest.approx(2 * np.tan(np.radians(20)))     # t <= 0.5: 40
    assert fov(7) == same(8) == pytest.approx(2 * np.tan(np.radians(30)))               # t >= 1.5: 60
    assert fov(5) == pytest.approx(2 * np.tan(np.radians(25)))                         # t = 1: 50


def test_eases_go_from_0_to_1_and_shape_the_middle():
    for name, ease in EASES.items():
        assert (ease(0.0), ease(1.0)) == (0.0, 1.0), name
    assert [EASES[n](0.5) for n in ("linear", "in", "out", "in_out")] == [0.5, 0.25, 0.75, 0.5]
    assert EASES["in_out"](0.25) == pytest.approx(0.15625)


def test_a_frame_is_the_same_whichever_frames_were_built_before(tmp_path):
    fresh = animation_of(tmp_path, SCENE).scene(6)
    a = animation_of(tmp_path, SCENE)
    for k in (8, 2, 6, 1, 6):
        s = a.scene(k)
    assert s.camera(16, 12).row.tolist() == fresh.camera(16, 12).row.tolist()
    assert [o.transform.tolist() for o in s.objects] == [o.transform.tolist() for o in fresh.objects]
    assert s.materials.kd.tolist() == fresh.materials.kd.tolist()


def test_shapes_and_textures_are_built_once_for_all_frames(tmp_path):
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    from PIL import Image
    Image.new("RGB", (2, 2), (200, 10, 10)).save(tmp_path / "t.png")
    a = animation_of(tmp_path, """\
        animation: {frames: 3, fps: 8}
        camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}
        objects:
          - {mesh: {file: m.obj}, transform: [{translate: {keys: {0: [0, 0, 0], 0.125: [1, 0, 0]}}}]}
          - {sphere: {}, material: {diffuse: {keys: {0: 1, 0.125: 0}}, texture: {image: t.png}}}
          - csg:
              union:
                - {sphere: {}, material: {diffuse: [1, 0, 0]}, transform: [{translate: {keys: {0: [0, 0, 0], 0.125: [0, 1, 0]}}}]}
                - {box: {}, material: {diffuse: [0, 1, 0]}}
          - {sphere: {}, material: {diffuse: [0, 0, 1]}}
        """)
    first, second = a.scene(1), a.scene(3)
    assert first.objects[0].shape is second.objects[0].shape                               # the mesh
    assert first.materials.materials[1].texture is second.materials.materials[1].texture  # the picture
    assert first.objects[3].shape is second.objects[3].shape
    for s in (first, second):                        # csg children's materials keep their rows
        assert s.materials.kd[s.objects[3].material].tolist() == [0, 0, 1]
        assert [s.materials.kd[c.material].tolist() for c in s.objects[2].shape.children] == [[1, 0, 0], [0, 1, 0]]
    assert second.objects[0].world_from_object.m[0, 3] == 1.0


def test_keyframes_in_an_included_file(tmp_path):
    (tmp_path / "inc.yaml").write_text("lights: [{position: {keys: {0: [0, 5, 0], 1: [0, 9, 0]}}}]\n")
    a = animation_of(tmp_path, "include: [inc.yaml]\nanimation: {frames: 2, fps: 1}\n"
                               "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n")
    assert a.scene(2).lights[0].position.tolist() == [0, 9, 0]


def test_a_still_load_of_an_animated_scene_is_its_first_frame(tmp_path):
    (tmp_path / "a.yaml").write_text(SCENE)
    scene = load_scene("a.yaml")
    assert scene.camera(16, 12).eye.tolist() == [0, 1, 6]
    animation, first, inputs = load_animation("a.yaml")
    assert first.camera(16, 12).eye.tolist() == [0, 1, 6] and inputs == [str(tmp_path / "a.yaml")]


def test_a_camera_transform_moves_eye_look_at_and_up(tmp_path):
    a = animation_of(tmp_path, """\
        camera:
          eye: [0, 0, 5]
          look_at: [0, 0, 4]
          transform: [{rotate: {axis: [0, 1, 0], degrees: 90}}, {translate: [0, 1, 0]}]
        """)
    cam = a.scene(1).camera(4, 4)
    np.testing.assert_allclose(cam.eye, [5, 1, 0], atol=1e-12)
    w = cam.origin + cam.right / 2 + cam.down / 2 - cam.eye              # toward the image's centre
    np.testing.assert_allclose(w / np.linalg.norm(w), [-1, 0, 0], atol=1e-12)


HEAD = "animation: {fps: 4, frames: 8}\nobjects: [{sphere: {}}]\n"


@pytest.mark.parametrize("camera, message", [
    ("{eye: {keys: {0: [0, 0, 5], 3: [0, 1, 5]}}, look_at: [0, 0, 0]}",
     "a.yaml:3:37: camera.eye.keys.3: time 3 is outside the clock range 0..2 s (8 frames at 4 fps)"),
    ("{eye: {keys: {1: [0, 0, 5], 0.5: [0, 1, 5]}}, look_at: [0, 0, 0]}",
     "a.yaml:3:37: camera.eye.keys.0.5: keyframes must be in increasing time: 0.5 follows 1"),
    ("{eye: {keys: {0: [0, 0, 5], 0: [0, 1, 5]}}, look_at: [0, 0, 0]}",
     "a.yaml:3:37: camera.eye.keys.0: duplicate key (first given at line 3)"),
    ("{eye: {keys: {0: [0, 5]}}, look_at: [0, 0, 0]}",
     "a.yaml:3:26: camera.eye.keys.0: must be a vector [x, y, z] of 3 numbers, got a list of 2"),
    ("{eye: {keys: {x: [0, 0, 5]}}, look_at: [0, 0, 0]}",
     "a.yaml:3:23: camera.eye.keys.x: a keyframe's time must be a number of seconds"),
    ("{eye: [0, 0, 5], look_at: [0, 0, 0], fov: {keys: {0: [40, 1, 1]}}}",
     "a.yaml:3:62: camera.fov.keys.0: must be a number, got a list of 3"),
    ("{eye: {keys: {0: [0, 0, 5]}, ease: bounce}, look_at: [0, 0, 0]}",
     "a.yaml:3:44: camera.eye.ease: must be one of linear, in, out, in_out, got 'bounce'"),
    ("{eye: {key: {0: [0, 0, 5]}}, look_at: [0, 0, 0]}",
     "a.yaml:3:16: camera.eye.key: unknown key (did you mean 'keys'?); allowed here: keys, ease"),
    ("{eye: {keys: {}}, look_at: [0, 0, 0]}",
     "a.yaml:3:22: camera.eye.keys: needs at least one keyframe, `time: value`"),
    ("{eye: [0, 0, 5], look_at: {x: 0, y: 1, z: 0}}",              # a vector written as a mapping
     "a.yaml:3:35: camera.look_at: must be a vector [x, y, z], or keyframes {keys: {time: value, ...}}; "
     "got a mapping without keys"),
    ("{eye: {keys: {true: [0, 0, 5]}}, look_at: [0, 0, 0]}",        # YAML's spelling of the key
     "a.yaml:3:23: camera.eye.keys.true: a keyframe's time must be a number of seconds"),
])
def test_keyframe_errors_are_located(tmp_path, camera, message):
    assert error_of(tmp_path, HEAD + f"camera: {camera}\n") == message


def test_an_error_that_a_frame_makes_names_the_frame_and_time(tmp_path):
    text = HEAD.replace("objects: [{sphere: {}}]", "objects: [{sphere: {}, transform: [{scale: {keys: {0: 1, 2: -1}}}]}]")
    text += "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
    assert error_of(tmp_path, text, frames=range(1, 9)) == ("a.yaml:2:44: objects[0].transform[0].scale: singular "
                                                           "transform (determinant 0) (at frame 5, time 1 s)")
    text = HEAD + "camera: {eye: [0, 0, 5], look_at: [0, 0, 0], up: {keys: {0: [0, 1, 0], 1: [0, 0, 1]}}}\n"
    assert error_of(tmp_path, text, frames=range(1, 9)) == ("a.yaml:3:75: camera.up: must not be parallel to the "
                                                           "view direction (look_at - eye) (at frame 5, time 1 s)")


def test_a_key_out_of_range_is_blamed_at_the_key_and_a_value_between_keys_at_its_frame(tmp_path):
    text = HEAD + ("camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
                   "lights: [{position: [0, 5, 0], color: {keys: {0: [1, 1, 1], 1: [1, -1, 1]}}}]\n")
    assert error_of(tmp_path, text) == "a.yaml:4:68: lights[0].color.keys.1[1]: must be a finite number >= 0, got -1"
    text = HEAD.replace("sphere: {}", "sphere: {}, material: {reflection: {keys: {0: 0, 0.75: 0, 1: 2}}}")
    text += "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n"
    assert error_of(tmp_path, text, frames=range(1, 9)) == \
        "a.yaml:2:73: objects[0].material.reflection[0]: must be at most 1, got 2 (at frame 5, time 1 s)"
    assert error_of(tmp_path, text.replace("1: 2", "1.5: 2"), frames=range(1, 9)) == \
        "a.yaml:2:47: objects[0].material.reflection[0]: must be at most 1, got 1.33333 (at frame 6, time 1.25 s)"


@pytest.mark.parametrize("section, message", [
    ("{fps: 4}", "a.yaml:1:12: animation: needs frames (a count) or clock ([start, end] in s)"),
    ("{frames: 4, clock: [0, 1]}", "a.yaml:1:12: animation: give the frame count (frames: 120) or the clock "
                                   "range (clock: [0, 5]), not both"),
    ("{frames: 0}", "a.yaml:1:21: animation.frames: must be in 1..100000, got 0"),
    ("{clock: [1, 1]}", "a.yaml:1:20: animation.clock: the end must come after the start, got [1, 1]"),
    ("{frames: 4, fps: -1}", "a.yaml:1:29: animation.fps: must be > 0, got -1"),
    ("{frames: 4, rate: 2}", "a.yaml:1:24: animation.rate: unknown key (did you mean 'frames'?); allowed here: fps, frames"),
    ("{frame: 3}", "a.yaml:1:13: animation.frame: unknown key (did you mean 'frames'?); allowed here: fps, frames, "
                   "clock"),
])
def test_animation_section_errors(tmp_path, section, message):
    assert error_of(tmp_path, f"animation: {section}\ncamera: {{eye: [0, 0, 5], look_at: [0, 0, 0]}}\n") == message


def test_keyframes_where_they_are_not_allowed(tmp_path):
    keyed = "keyframes, which only the values listed under Animation in docs/scene-format.md take, " \
            "in a scene with an `animation:` section"
    assert error_of(tmp_path, "camera: {eye: {keys: {0: [0, 0, 5]}}, look_at: [0, 0, 0]}\n") == \
        f"a.yaml:1:15: camera.eye: must be a vector [x, y, z] of 3 numbers, got {keyed}"
    assert error_of(tmp_path, HEAD.replace("sphere: {}", "sphere: {radius: {keys: {0: 1}}}")
                    + "camera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\n") == \
        f"a.yaml:2:29: objects[0].sphere.radius: must be a number, got {keyed}"
