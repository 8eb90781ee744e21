"""Recording alone: a countdown before recording (sidebar and 3D View header), and the takes list of this
.blend (bake, rename, reveal, delete). The countdown's timer is driven by hand with a fake clock."""
from __future__ import annotations

import os
import time

import bpy
import pytest

from kinect_retarget.blender.live import live_runtime as live
from kinect_retarget.blender.live import record_countdown
from kinect_retarget.sources import TakePlayback


@pytest.fixture
def live_rig(generated_live_rig, monkeypatch):
    take, s = generated_live_rig
    now = [100.0]
    monkeypatch.setattr(record_countdown, "clock", lambda: now[0])
    c = live.start_live(bpy.context, source=TakePlayback(take, speed=1.0, loop=True), use_timer=False)
    return c, s, now


def _header_funcs():
    return getattr(bpy.types.VIEW3D_HT_header.draw, "_draw_funcs", [])


def test_countdown_then_recording_and_cancel(live_rig):
    c, s, now = live_rig
    s.record_countdown = "3"
    assert record_countdown.draw_header in _header_funcs()
    assert bpy.ops.kinect_retarget.record() == {"FINISHED"}
    assert c.recording is None and record_countdown.label() == "Recording in 3…"
    now[0] += 1.2
    assert record_countdown.tick() == record_countdown.TICK and c.recording is None
    assert record_countdown.label() == "Recording in 2…"
    now[0] += 1.9
    assert record_countdown.tick() is None  # time is up: recording starts, the timer ends
    assert c.recording is not None and record_countdown.remaining() is None
    c.stop_recording(bake=False)
    # Record during a countdown calls it off; so does stopping live
    assert bpy.ops.kinect_retarget.record() == {"FINISHED"} and record_countdown.remaining() == 3.0
    assert bpy.ops.kinect_retarget.record() == {"FINISHED"}
    assert record_countdown.remaining() is None and c.recording is None
    bpy.ops.kinect_retarget.record()
    live.stop_live(bake=False)
    assert record_countdown.remaining() is None


def test_countdown_off_records_at_once(live_rig):
    c, s, _ = live_rig
    assert s.record_countdown == "0"
    bpy.ops.kinect_retarget.record()
    assert c.recording is not None and record_countdown.label() == ""


def _record(c, frames=15):
    c.start_recording(bpy.context)
    end = time.perf_counter() + 30
    while c.session.recorder is None or c.session.recorder.frames < frames:
        live.pump_live()
        time.sleep(0.003)
        assert time.perf_counter() < end
    return c.stop_recording(bake=False)


def test_takes_list_bake_rename_reveal_delete(live_rig):
    c, s, _ = live_rig
    path = _record(c)
    live.stop_live(bake=False)
    assert len(s.takes) == 1
    item = s.takes[0]
    assert item.path == path and item.name == os.path.splitext(os.path.basename(path))[0]
    assert item.frames >= 15 and item.seconds > 0.3 and item.date[:2] == "20"
    # bake with the sidebar's options: onto the target, scene left as it was
    assert bpy.ops.kinect_retarget.take_bake(index=0) == {"FINISHED"}
    assert s.armature.animation_data.action is not None and bpy.context.scene.render.fps == 24
    # rename: file and entry follow; an existing name is refused
    assert bpy.ops.kinect_retarget.take_rename(index=0, new_name="warm up") == {"FINISHED"}
    renamed = os.path.join(os.path.dirname(path), "warm up.krtake")
    assert os.path.isfile(renamed) and not os.path.exists(path) and s.takes[0].name == "warm up"
    open(os.path.join(os.path.dirname(path), "taken.krtake"), "w").close()
    with pytest.raises(RuntimeError, match="already exists"):
        bpy.ops.kinect_retarget.take_rename(index=0, new_name="taken")
    # delete (EXEC: the confirmation is the invoke's): the file goes, and the entry
    assert bpy.ops.kinect_retarget.take_delete(index=0) == {"FINISHED"}
    assert not os.path.exists(renamed) and len(s.takes) == 0


def test_takes_list_reports_a_missing_file(live_rig):
    c, s, _ = live_rig
    path = _record(c)
    os.remove(path)
    for op in (bpy.ops.kinect_retarget.take_reveal, bpy.ops.kinect_retarget.take_bake):
        with pytest.raises(RuntimeError, match="is gone"):
            op(index=0)


class _AnyLayout:
    """Accepts whatever a panel's draw() asks of a layout, remembering the labels and operator texts."""
    def __init__(self, seen):
        self.__dict__["seen"] = seen

    def __getattr__(self, name):
        def call(*args, **kwargs):
            if name in ("label", "operator"):
                self.seen.append(kwargs.get("text", args[0] if args else ""))
            return self
        return call

    def __setattr__(self, name, value):
        pass


def test_panels_draw_the_countdown_and_the_takes(live_rig):
    from types import SimpleNamespace
    from kinect_retarget.blender.ui import panels, takes_list
    c, s, now = live_rig
    _record(c)
    s.record_countdown = "5"
    bpy.ops.kinect_retarget.record()
    seen = []
    main = panels.KINECT_RETARGET_PT_main
    main.draw(SimpleNamespace(layout=_AnyLayout(seen), _draw_status=main._draw_status), bpy.context)
    assert "Recording in 5…" in seen and "Cancel Countdown" in seen
    header = []
    record_countdown.draw_header(SimpleNamespace(layout=_AnyLayout(header)), bpy.context)
    assert header == ["Recording in 5…"]
    for cls in (panels.KINECT_RETARGET_PT_options, panels.KINECT_RETARGET_PT_bake,
                takes_list.KINECT_RETARGET_PT_takes):
        cls.draw(SimpleNamespace(layout=_AnyLayout(seen)), bpy.context)
    assert "Bake Take…" in seen
