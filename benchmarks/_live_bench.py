"""Shared set-up for the live benchmarks: a generated rig in a registered scene, driven like the timer does."""
from __future__ import annotations

import time

from _common import SAMPLE_TAKES

TAKE = SAMPLE_TAKES / "kinect_v2_ges03_drawlines.krtake"


def live_scene(speed: float, loop: bool = True, filter_name: str = "default"):
    import bpy

    import kinect_retarget
    from kinect_retarget.blender.io.kinect_rig import build_kinect_rig
    from kinect_retarget.core.kinect_rig_layout import median_segment_lengths
    from kinect_retarget.takes import load_take

    take = load_take(TAKE)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    kinect_retarget.register()
    obj = build_kinect_rig(bpy.context.scene, take.skeleton, median_segment_lengths(take), "KinectRig")
    bpy.context.view_layer.objects.active = obj
    s = bpy.context.scene.kinect_retarget
    s.initialised, s.source, s.take_path, s.speed, s.loop = True, "TAKE", str(TAKE), speed, loop
    s.armature, s.filter, s.play_on_record = obj, filter_name, False
    return take, obj


def pump_like_the_timer(seconds: float, interval: float, on_tick=None) -> None:
    """Call the pump every `interval` seconds (what bpy.app.timers does with TIMER_INTERVAL), plus the
    depsgraph update a viewport redraw would do after a pose change."""
    import bpy

    from kinect_retarget.blender.live import live_runtime as live

    view_layer = bpy.context.view_layer
    start = time.perf_counter()
    next_tick = start
    while time.perf_counter() - start < seconds:
        if not live.pump_live():
            break
        view_layer.update()
        if on_tick:
            on_tick()
        next_tick += interval
        delay = next_tick - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        else:
            next_tick = time.perf_counter()
