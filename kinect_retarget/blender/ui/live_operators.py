"""The live operators: Start Live (with a pass-through modal handler, so Esc stops live and errors reach
report()), Stop Live, Record and Calibrate. Each is thin: live_runtime does the work."""
from __future__ import annotations

import bpy

from ...core.take import TakeError
from ...sources import SourceError
from ..live import live_runtime, record_countdown
from ..live.window_context import in_window
from .properties import target_armature


def _flush_reports(op, controller=None) -> None:
    """Pass a controller's queued reports to the operator (default: the running one; a stopped one's last
    words are passed explicitly)."""
    c = controller if controller is not None else live_runtime.controller()
    for level, msg in (c.reports if c else []):
        op.report({level}, msg)
    if c:
        c.reports.clear()


class KINECT_RETARGET_OT_live_start(bpy.types.Operator):
    """Drive the target armature live from the chosen source (Esc stops)"""
    bl_idname = "kinect_retarget.live_start"
    bl_label = "Start Live"
    bl_options = {"REGISTER"}  # no UNDO: live pushes no undo steps

    _timer = None
    _ctrl = None

    @classmethod
    def poll(cls, context):
        if live_runtime.controller() is not None:
            cls.poll_message_set("Live is already running")
            return False
        if target_armature(context) is None:
            cls.poll_message_set("Pick a target armature (or make one active)")
            return False
        return True

    def execute(self, context):
        try:
            self._ctrl = live_runtime.start_live(context)
        except (SourceError, ValueError, TakeError) as exc:
            live_runtime.set_error_status(str(exc))
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        self.report({"INFO"}, self._ctrl.message)
        return {"FINISHED"}

    def invoke(self, context, event):
        if self.execute(context) != {"FINISHED"}:
            return {"CANCELLED"}
        if context.window is None:  # no window (background): the timer alone drives live
            return {"FINISHED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC" and event.value == "PRESS" and live_runtime.controller() is self._ctrl:
            _flush_reports(self)
            live_runtime.stop_live(context=context)
        if live_runtime.controller() is not self._ctrl or self._ctrl is None:
            _flush_reports(self, self._ctrl)
            context.window_manager.event_timer_remove(self._timer)
            return {"CANCELLED"} if self._ctrl and self._ctrl.session.error else {"FINISHED"}
        if event.type == "TIMER":
            _flush_reports(self)
        return {"PASS_THROUGH"}


class KINECT_RETARGET_OT_live_stop(bpy.types.Operator):
    """Stop live; a recording in progress is kept, and baked when Bake on Stop is on"""
    bl_idname = "kinect_retarget.live_stop"
    bl_label = "Stop Live"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return live_runtime.controller() is not None

    def execute(self, context):
        c = live_runtime.controller()
        live_runtime.stop_live(context=context)
        _flush_reports(self, c)
        return {"FINISHED"}


def _record_after_countdown() -> None:
    """The countdown's end (a timer, whose context has no window): record as the Record button would."""
    c = live_runtime.controller()
    if c is None:
        return
    try:
        in_window(lambda: c.start_recording(bpy.context))
    except (SourceError, OSError) as exc:
        c.post("ERROR", str(exc))
    live_runtime.redraw_3d_views()


class KINECT_RETARGET_OT_record(bpy.types.Operator):
    """Start recording the live frames to a take, or stop and bake the recording onto the rig"""
    bl_idname = "kinect_retarget.record"
    bl_label = "Record"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        if live_runtime.controller() is None:
            cls.poll_message_set("Start live first")
            return False
        return True

    def execute(self, context):
        c = live_runtime.controller()
        try:
            if c.recording is None:
                if record_countdown.cancel():  # Record during the countdown calls it off
                    self.report({"INFO"}, "Countdown cancelled: not recording")
                    return {"FINISHED"}
                seconds = int(context.scene.kinect_retarget.record_countdown)
                if seconds:
                    record_countdown.start(seconds, _record_after_countdown)
                    self.report({"INFO"}, f"Recording starts in {seconds} s")
                    return {"FINISHED"}
                path = c.start_recording(context)
                self.report({"INFO"}, f"Recording to {path}")
            else:
                c.stop_recording(bake=context.scene.kinect_retarget.bake_on_stop, context=context)
                _flush_reports(self)
        except (SourceError, OSError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        return {"FINISHED"}


class KINECT_RETARGET_OT_calibrate(bpy.types.Operator):
    """Capture one second of the performer standing (T-pose or A-pose) to fix the root scale for this rig"""
    bl_idname = "kinect_retarget.calibrate"
    bl_label = "Calibrate"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        if live_runtime.controller() is None:
            cls.poll_message_set("Start live first, then stand still in a T-pose or A-pose")
            return False
        return not live_runtime.controller().session.calibrating

    def execute(self, context):
        live_runtime.controller().calibrate(1.0)
        self.report({"INFO"}, "Calibrating: stand still for one second")
        return {"FINISHED"}


CLASSES = (KINECT_RETARGET_OT_live_start, KINECT_RETARGET_OT_live_stop, KINECT_RETARGET_OT_record,
           KINECT_RETARGET_OT_calibrate)
