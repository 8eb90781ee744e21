"""The bake that runs when a recording stops is one undo step holding the Action and its assignment: Ctrl+Z
(ed.undo) right after takes back exactly the bake, Ctrl+Shift+Z (ed.redo) brings it back. Headless bpy has
a window and an undo stack, so the real operators run here."""
from __future__ import annotations

import time

import bpy
import pytest

from kinect_retarget.blender.live import live_runtime as live
from kinect_retarget.sources import TakePlayback


@pytest.fixture
def rig(generated_live_rig):
    take, s = generated_live_rig
    s.bake_on_stop = True
    bpy.ops.ed.undo_push(message="rig made")  # what the user did before going live
    return take.slice(slice(0, 45))


def _record_until_the_take_ends(take) -> str:
    c = live.start_live(bpy.context, source=TakePlayback(take, speed=4.0), use_timer=False)
    c.start_recording(bpy.context)
    end = time.perf_counter() + 60
    while live.pump_live() and time.perf_counter() < end:  # the take ends live; Bake on Stop bakes
        time.sleep(0.003)
    assert live.controller() is None
    return c.baked_action


def _assigned(name="KinectRig"):
    ad = bpy.data.objects[name].animation_data  # by name: undo reloads the data, old references die
    return ad.action.name if ad is not None and ad.action is not None else None


def test_bake_on_stop_is_one_undo_step(rig):
    baked = _record_until_the_take_ends(rig)
    assert baked and _assigned() == baked and baked in bpy.data.actions
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert _assigned() is None and baked not in bpy.data.actions  # Action and assignment gone together
    assert "KinectRig" in bpy.data.objects  # ... and nothing before the bake (the rig stays)
    assert bpy.ops.ed.redo() == {"FINISHED"}
    assert _assigned() == baked and len(bpy.data.actions[baked].layers[0].strips[0].channelbags[0].fcurves) > 0


def test_record_operator_stop_is_one_undo_step_while_live_goes_on(rig):
    c = live.start_live(bpy.context, source=TakePlayback(rig, speed=1.0, loop=True), use_timer=False)
    c.start_recording(bpy.context)
    end = time.perf_counter() + 30
    while c.session.recorder is None or c.session.recorder.frames < 10:
        live.pump_live()
        time.sleep(0.003)
        assert time.perf_counter() < end
    c.stop_recording(bake=True, context=bpy.context)  # what the Record button does while live runs
    baked = c.baked_action
    assert baked and _assigned() == baked
    live.stop_live(bake=False)
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert baked not in bpy.data.actions and _assigned() is None
