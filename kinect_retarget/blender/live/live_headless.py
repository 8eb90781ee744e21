"""The `live` command's Blender side: open the rig (or build the generated one), run the pump loop, bake the
recording, save. Settings go straight to start_live; the scene's sidebar settings are left as they were."""
from __future__ import annotations

import os
import time

import bpy

from ...core.pipeline import RetargetSettings
from ...sources import SourceError
from ..bake_take import set_scene_rate
from ..headless import blender_message, find_armature, open_target, save_blend
from ..io.kinect_rig import build_kinect_rig
from .live_controller import LiveSettings
from .live_runtime import pump_live, start_live, stop_live


def run_headless(source, seconds: float, *, rig_path=None, armature=None, preset="auto",
                 filter_name="default", root="xyz", mirror=False, overrides=None, record=None, out=None,
                 rig_lengths=None, performers=None) -> dict:
    """Run live for `seconds` (or until the source ends) on the rig in `rig_path` (or the generated one with
    `rig_lengths`), record to `record` and bake it, save `out`. Returns the statistics. `performers`
    [(body, armature name or None)]: one rig per body of the source (the named armatures of `rig_path`, or a
    generated rig each), the first leading; `armature` is the one rig's name without it."""
    from ... import register, unregister

    performers = list(performers or [(0, armature)])
    several = len(performers) > 1

    def generate(scene):
        rigs = [build_kinect_rig(scene, source.skeleton, rig_lengths, f"KinectRig_body{b}" if several else "KinectRig")
                for b, _ in performers]
        set_scene_rate(scene, source.rate)  # a new scene runs at the source's rate, as `bake` sets it
        return rigs[0]

    obj, preset = open_target(rig_path, performers[0][1], preset, generate)
    if rig_path:
        others = [(find_armature(name), b) for b, name in performers[1:]]
    else:
        others = [(bpy.data.objects[f"KinectRig_body{b}"], b) for b, _ in performers[1:]]
    register()   # once the rig is there: neither opening nor building it needs the add-on
    try:
        bpy.context.view_layer.objects.active = obj
        # the command bakes what it records, also when the source ends first
        settings = LiveSettings(preset=preset, retarget=RetargetSettings(filter=filter_name, root_mode=root,
                                                                          mirror=mirror),
                                bake_on_stop=bool(record))
        try:
            c = start_live(bpy.context, source, settings, overrides or None, armature=obj, use_timer=False,
                           body=performers[0][0], followers=others)
        except SourceError as exc:
            raise ValueError(str(exc)) from None
        if record:
            try:
                c.start_recording(bpy.context, os.path.abspath(record), play=False)
            except SourceError as exc:  # unwritable path: bad input, one line for the user
                raise ValueError(str(exc)) from None
        start = time.perf_counter()
        while time.perf_counter() - start < seconds and pump_live():
            time.sleep(0.002)
        elapsed = time.perf_counter() - start
        idle_reason = getattr(source, "idle_reason", None)
        if c.session.stats.received == 0 and not c.session.error and idle_reason is not None:
            c.session.stop(idle_reason())  # a device that delivered nothing is a failed run, not an empty one
        stop_live(bake=bool(record))
        result = {"seconds": round(elapsed, 3), "armature": obj.name, **c.session.statistics(),
                  "error": c.session.error, "record": os.path.abspath(record) if record else None,
                  "action": c.baked_action, "warning": source.warning}
        if c.followers:
            result["performers"] = [{"armature": f.obj_name, "body": f.body, "action": f.baked_action,
                                     "error": f.session.error, **f.session.statistics()} for f in (c, *c.followers)]
        if hasattr(source, "bad_packets"):
            result["bad_packets"] = source.bad_packets
        if out:
            try:
                save_blend(out)
            except RuntimeError as exc:  # the recording (if any) is already on disk
                raise ValueError(f"{out}: cannot save ({blender_message(exc)})") from None
            result["out"] = os.path.abspath(out)
    finally:
        stop_live(bake=False)
        unregister()
    return result
