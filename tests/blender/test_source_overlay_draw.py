"""The source skeleton's real draw callback (source_overlay._draw) run against recording stand-ins for Blender's
`gpu` and `gpu_extras.batch` modules, since headless Blender refuses GPU calls. The stand-ins accept only what
Blender 5.0 accepts (builtin shader names and their uniforms as gpu_py_shader.cc lists them, batch types, and
float32 (N, comps) vertex data, which GPUVertBuf.attr_fill copies as raw bytes), and record every call: one
batch of lines per skeleton with the bones' vertex count and tracking-state colours, one of points for the
joints, the uniforms, and the GPU state put back afterwards. (Real drawing in a Blender window has still not
been seen.)"""
from __future__ import annotations

import sys
import types

import bpy
import numpy as np
import pytest

from kinect_retarget.blender.ui import source_overlay
from kinect_retarget.core.skeleton_overlay import COLORS
from kinect_retarget.core.skeletons import INFERRED, KINECT_V2, NOT_TRACKED, TRACKED
from tests.blender.test_source_overlay import scene  # noqa: F401 (the fixture)

# Blender 5.0's builtin shaders: attributes (name -> components) and uniforms (gpu_py_shader.cc)
SHADERS = {
    "FLAT_COLOR": ({"pos": 3, "color": 4}, set()), "SMOOTH_COLOR": ({"pos": 3, "color": 4}, set()),
    "UNIFORM_COLOR": ({"pos": 3}, {"color"}),
    "IMAGE": ({"pos": 3, "texCoord": 2}, {"image"}), "IMAGE_COLOR": ({"pos": 3, "texCoord": 2}, {"image", "color"}),
    "POLYLINE_FLAT_COLOR": ({"pos": 3, "color": 4}, {"viewportSize", "lineWidth"}),
    "POLYLINE_SMOOTH_COLOR": ({"pos": 3, "color": 4}, {"viewportSize", "lineWidth"}),
    "POLYLINE_UNIFORM_COLOR": ({"pos": 3}, {"viewportSize", "lineWidth", "color"}),
    "POINT_FLAT_COLOR": ({"pos": 3, "color": 4}, {"size"}),
    "POINT_UNIFORM_COLOR": ({"pos": 3}, {"color", "size"}),
}
BATCH_TYPES = {"POINTS", "LINES", "TRIS", "LINES_ADJ"}
BLENDS = {"NONE", "ALPHA", "ALPHA_PREMULT", "ADDITIVE", "ADDITIVE_PREMULT", "MULTIPLY", "SUBTRACT", "INVERT"}
DEPTHS = {"NONE", "ALWAYS", "LESS", "LESS_EQUAL", "EQUAL", "GREATER", "GREATER_EQUAL"}
VIEWPORT = (0, 0, 1280, 720)


class Recorder:
    """The fake gpu module's state and the record of what was drawn."""

    def __init__(self):
        self.state = {"blend": "MULTIPLY", "depth": "LESS_EQUAL", "line_width": 1.5, "program_point_size": False}
        self.draws = []  # (shader name, batch type, content, uniforms, state at draw time)
        self.bound = None

    def module(self):
        rec = self

        class Shader:
            def __init__(self, name):
                self.name, self.uniforms = name, {}

            def bind(self):
                rec.bound = self

            def uniform_float(self, name, value):
                if name not in SHADERS[self.name][1]:
                    raise ValueError(f"GPUShader.uniform_float: uniform {name} not found")
                assert rec.bound is self, "uniform set on an unbound shader"
                # like Blender: a float or int, or a sequence of 2-4, 9 or 16 floats
                assert isinstance(value, (int, float)) or len(value) in (2, 3, 4, 9, 16), value
                self.uniforms[name] = np.asarray(value, dtype=float).tolist()

        def from_builtin(name, config="DEFAULT"):
            if name not in SHADERS:
                raise ValueError(f"expected a value in {sorted(SHADERS)}, got {name!r}")
            return Shader(name)

        def setter(key, allowed=None):
            def set_(value):
                assert allowed is None or value in allowed, (key, value)
                rec.state[key] = value
            return set_

        state = types.SimpleNamespace(
            blend_get=lambda: rec.state["blend"], blend_set=setter("blend", BLENDS),
            depth_test_get=lambda: rec.state["depth"], depth_test_set=setter("depth", DEPTHS),
            line_width_get=lambda: rec.state["line_width"], line_width_set=setter("line_width"),
            program_point_size_set=setter("program_point_size"), point_size_set=setter("point_size"),
            viewport_get=lambda: VIEWPORT)

        class Batch:
            def __init__(self, shader, kind, content):
                attrs = SHADERS[shader.name][0]
                assert kind in BATCH_TYPES and set(content) == set(attrs), (kind, sorted(content))
                n = {len(v) for v in content.values()}
                assert len(n) == 1, "attributes of different lengths"
                for name, data in content.items():  # attr_fill copies a buffer's bytes as they are
                    assert isinstance(data, np.ndarray) and data.dtype == np.float32 and data.flags.c_contiguous
                    assert data.ndim == 2 and data.shape[1] == attrs[name], (name, data.shape)
                self.shader, self.kind, self.content = shader, kind, {k: v.copy() for k, v in content.items()}

            def draw(self, shader=None):
                shader = shader or self.shader
                rec.draws.append((shader.name, self.kind, self.content, dict(shader.uniforms), dict(rec.state)))

        gpu = types.SimpleNamespace(shader=types.SimpleNamespace(from_builtin=from_builtin), state=state)
        batch = types.ModuleType("gpu_extras.batch")
        batch.batch_for_shader = lambda shader, kind, content: Batch(shader, kind, content)
        extras = types.ModuleType("gpu_extras")
        extras.batch = batch
        return gpu, extras, batch


@pytest.fixture
def recorder(monkeypatch):
    rec = Recorder()
    gpu, extras, batch = rec.module()
    monkeypatch.setitem(sys.modules, "gpu", gpu)
    monkeypatch.setitem(sys.modules, "gpu_extras", extras)
    monkeypatch.setitem(sys.modules, "gpu_extras.batch", batch)
    return rec


@pytest.fixture
def duo(request):
    """test_source_overlay's two-performer scene, the source shown, Bob following body 1."""
    sc, rigs, takes, _ = request.getfixturevalue("scene")
    s = sc.kinect_retarget
    s.show_source = True
    item = s.performers.add()
    item.armature, item.body = rigs[1], 1
    return sc, rigs, takes


def _expected_colors(states):
    return {s: np.array(COLORS[s], dtype=np.float32) for s in (TRACKED, INFERRED) if s in states}


def test_the_draw_callback_draws_each_performer_as_lines_and_points(duo, recorder):
    sc, rigs, (a, b) = duo
    sc.frame_set(11)                       # take sample 10 for both bodies
    source_overlay._draw()
    assert getattr(source_overlay._draw, "last_error", None) is None or recorder.draws
    kinds = [(name, kind) for name, kind, *_ in recorder.draws]
    assert kinds == [("POLYLINE_FLAT_COLOR", "LINES"), ("POINT_FLAT_COLOR", "POINTS")] * 2  # one of each per body
    parents = KINECT_V2.parent_array
    for (_, _, lines, lu, ls), (_, _, points, pu, ps), take in zip(recorder.draws[::2], recorder.draws[1::2], (a, b)):
        states = take.states[10]
        shown = states != NOT_TRACKED
        bones = [j for j in range(len(states)) if parents[j] >= 0 and shown[j] and shown[parents[j]]]
        assert len(lines["pos"]) == 2 * len(bones) and len(points["pos"]) == int(shown.sum())
        want = _expected_colors(states)
        # each bone takes the colour of its less certain end; each joint its own state's colour
        bone_state = np.minimum(states[parents[bones]], states[bones])
        np.testing.assert_array_equal(lines["color"], np.repeat([want[s] for s in bone_state], 2, axis=0))
        np.testing.assert_array_equal(points["color"], [want[s] for s in states[shown]])
        assert len(want) == 2 or set(states[shown]) == {TRACKED}          # both colours when the take has both
        assert lu == {"viewportSize": [1280.0, 720.0], "lineWidth": source_overlay.LINE_WIDTH}
        assert pu == {"size": source_overlay.POINT_SIZE}
        for st in (ls, ps):  # while drawing: blended, in front of the character, the point size from the shader
            assert st["blend"] == "ALPHA" and st["depth"] == "NONE" and st["program_point_size"] is True
        # the lines join each bone's parent joint to the joint, at the joints drawn as points
        ends = lines["pos"].reshape(-1, 2, 3)
        np.testing.assert_allclose(ends[:, 1], points["pos"][np.searchsorted(np.flatnonzero(shown), bones)], atol=0)
    # Bob's skeleton stands beside Bob (3 m along X), Alice's beside Alice
    alice_x, bob_x = recorder.draws[1][2]["pos"][:, 0].mean(), recorder.draws[3][2]["pos"][:, 0].mean()
    assert 2.0 < bob_x - alice_x < 4.0
    assert recorder.state == {"blend": "MULTIPLY", "depth": "LESS_EQUAL", "line_width": 1.5,
                              "program_point_size": False}                      # everything put back


def test_the_draw_callback_survives_no_armature_no_take_and_a_gpu_error(duo, recorder):
    sc, (alice, bob), _ = duo
    s = sc.kinect_retarget
    sc.frame_set(-500)                     # before the take: its first frame, not an error
    source_overlay._draw()
    assert len(recorder.draws) == 4
    recorder.draws.clear()
    bpy.data.objects.remove(alice)         # the target armature deleted: only the other performer is drawn
    bpy.data.objects.remove(bob)
    source_overlay._draw()
    assert recorder.draws == []
    s.take_path = "/nonexistent/take.krtake"
    source_overlay._draw()                 # a take that cannot load: nothing drawn, nothing raised
    s.take_path = ""
    source_overlay._draw()
    assert recorder.draws == []
    assert recorder.state["blend"] == "MULTIPLY" and recorder.state["depth"] == "LESS_EQUAL"


def test_a_gpu_failure_is_reported_once_and_the_state_put_back(duo, recorder, capsys, monkeypatch):
    gpu = sys.modules["gpu"]

    def broken(name, config="DEFAULT"):
        raise ValueError("expected a builtin shader name")
    monkeypatch.setattr(gpu.shader, "from_builtin", broken)
    source_overlay._draw.__dict__.pop("last_error", None)
    source_overlay._draw()
    source_overlay._draw()
    out = capsys.readouterr().out
    assert out.count("source skeleton not drawn: expected a builtin shader name") == 1
    assert recorder.draws == [] and recorder.state["blend"] == "MULTIPLY"
