"""Live puppeteering in Blender. Sources run on threads; everything here runs on the main thread.

A `bpy.app.timers` callback pumps the bpy-free LiveSession (drain, filter, retarget, record) and poses the
rig with the newest frame. Headless code (CLI, tests) calls `pump_live()` itself, since timers do not fire
while a script blocks. The Start Live operator also runs a pass-through modal handler so Esc stops live and
errors reach `report()`. Live pushes no undo steps and holds object names, never bpy references.
"""
from __future__ import annotations

import os
import sys
import time
from dataclasses import replace

import bpy
import numpy as np
from bpy.app.handlers import persistent

from ...core.parent_fit import relative_to_parent
from ...core.pipeline import RetargetSettings
from ...core.take import TakeError
from ...core.performer_calibration import PROPERTY as CALIBRATION_PROPERTY, Calibration, CalibrationError
from ...live.session import LiveSession
from ...sources import OscReceiver, SourceError, TakePlayback, UsbKinectSource
from ...takes import load_take
from ..bake_take import bake_take, make_pipeline, set_scene_rate
from ..ui.bake_settings import recording_bake_options
from .osc_access import osc_host
from .undo_step import push_undo_step
from ..ui.mapping_table import table_overrides
from ..io.pose_apply import apply_frame_pose, restore_pose, snapshot_pose
from ..io.armature_probe import ArmatureEvaluator, constrained_summary, probe_parents, read_rotations, solve_frames
from ..ui.preferences import get_preferences
from ..ui.properties import ensure_defaults, target_armature
from ..io.rig_reader import fk_switch_bones, has_constrained_ancestry

usb_source_factory = None  # set by the USB panel (usb_panel.py): simulated Kinect, device freed from its preview
TIMER_INTERVAL = 1 / 120  # pump often: latency is arrival -> applied, and an empty pump costs microseconds

_controller: "LiveController | None" = None
_last_status: dict = {"state": "idle", "message": "", "error": None, "stats": None}


class LiveController:
    def __init__(self, scene, obj, session: LiveSession, preset: str, overrides, settings: RetargetSettings,
                 source_label: str, saved: dict):
        self.scene_name, self.obj_name = scene.name, obj.name
        self.session = session
        self.preset, self.overrides, self.settings = preset, overrides, settings
        self.source_label = source_label
        self.reports: list[tuple[str, str]] = []
        self.message = f"Live: {source_label} -> {obj.name}"
        self.recording: dict | None = None
        self.baked_action: str | None = None
        self.started_at = time.perf_counter()
        self._saved = saved   # the rig's pose, action and switches before live: put back by finish()
        self._rigify_fk(obj)
        self._switches = {name: 1.0 for name in fk_switch_bones(obj)}   # the copy is set the same way
        pipeline = session.pipeline
        self.model = None       # learned constrained parents (issue 15): exact live poses in numpy
        self.evaluator = None   # the armature copy for Exact on Constrained Rigs, only with fallback bones
        if has_constrained_ancestry(obj, pipeline.bone_names):
            with ArmatureEvaluator(obj, pipeline.rig.bone_names, self._switches) as evaluator:
                self.model = probe_parents(evaluator, obj, pipeline.rig, pipeline.bone_names, pipeline.root_bone)
            self.reports.append(("WARNING" if self.model.fallback else "INFO", constrained_summary(self.model)))
        fallback = self.model is not None and bool(self.model.fallback)
        self.update_after_apply = bool(bpy.app.background) and fallback
        # exact costs Blender evaluations, so it is asked for only where a bone has no learned relation
        self.exact = bool(scene.kinect_retarget.exact_constrained) and fallback

    # -- helpers -------------------------------------------------------------------------------------------
    def obj(self):
        return bpy.data.objects.get(self.obj_name)

    def scene(self):
        return bpy.data.scenes.get(self.scene_name)

    def post(self, level: str, message: str) -> None:
        """For report(): the modal operator passes these on; the panel shows the last one."""
        self.reports.append((level, message))
        if level == "ERROR":
            _last_status["error"] = message
        self.message = message
        print(f"kinect_retarget: {message}", file=sys.stderr)

    def _rigify_fk(self, obj) -> None:
        # the preset drives Rigify's FK controls: switch the limbs to FK while live (restored on stop)
        for name in fk_switch_bones(obj):
            obj.pose.bones[name]["IK_FK"] = 1.0

    def apply(self, pose) -> None:
        obj = self.obj()
        if obj is None:
            raise RuntimeError(f"armature {self.obj_name!r} no longer exists")
        model = self.model
        if model is not None:
            if self.exact:  # fallback bones evaluated on the armature copy until they settle
                if self.evaluator is None:
                    self.evaluator = ArmatureEvaluator(obj, model.rig.bone_names, self._switches)
                pose.quats = solve_frames(self.evaluator, model, pose.desired[None], pose.root_bone,
                                          pose.root_location[None])[0]
            else:  # fallback bones (if any) as the viewport last evaluated them: one frame late
                pose.quats = model.solve(pose.desired[None], self._evaluated(obj) if model.fallback else None)[0]
        apply_frame_pose(obj, pose)
        if self.update_after_apply:
            bpy.context.view_layer.update()  # no viewport redraw to evaluate the fallback bones

    def release_evaluator(self) -> None:
        """Remove the armature copy and its scene (stop, and before a save: it must not be saved)."""
        if self.evaluator is not None:
            self.evaluator.close()
            self.evaluator = None

    def _evaluated(self, obj) -> dict:
        """Fallback bones' rotations relative to their parents, as Blender last evaluated the rig."""
        pose_bones = obj.pose.bones
        if getattr(self, "_pose_index", None) is None or len(pose_bones) != len(self._flat) // 16:
            where = {n: i for i, n in enumerate(pose_bones.keys())}
            self._pose_index = np.array([where[n] for n in self.model.rig.bone_names])
            self._flat = np.empty(len(pose_bones) * 16, dtype=np.float32)
        rotations = read_rotations(pose_bones, self._pose_index, self._flat)
        return relative_to_parent(self.model.rig, self.model.fallback, rotations[None])

    # -- pumping ---------------------------------------------------------------------------------------------
    def pump(self) -> bool:
        alive = self.session.pump()
        if not alive:
            self.finish()
        return alive

    # -- recording ---------------------------------------------------------------------------------------------
    def start_recording(self, context, path: str | None = None) -> str:
        scene = self.scene()
        s = scene.kinect_retarget
        stamp = time.strftime("%Y%m%d_%H%M%S")
        if path is None:
            folder = bpy.path.abspath(s.record_dir or "//kinect_takes/")
            if folder.startswith("//") or not os.path.isabs(folder):  # unsaved file: // has no meaning
                folder = os.path.join(bpy.app.tempdir or os.path.expanduser("~"), "kinect_takes")
            path, suffix = _unused_path(folder, f"{bpy.path.clean_name(self.obj_name)}_{stamp}", ".krtake")
            stamp += suffix  # the action is named like its file
        name = f"{self.obj_name}_live_{stamp}"
        try:
            self.session.start_recording(path, {"name": name, "armature": self.obj_name,
                                                "source": self.source_label})
        except OSError as exc:
            raise SourceError(f"cannot write the recording {path}: {exc.strerror or exc}") from None
        fps = scene.render.fps / scene.render.fps_base
        self.recording = {"path": path, "name": name, "frame_start": scene.frame_current, "fps": fps,
                          "playing": False}
        if s.play_on_record and context is not None and context.screen is not None \
                and not context.screen.is_animation_playing:
            bpy.ops.screen.animation_play()
            self.recording["playing"] = True
        self.message = f"Recording to {path}"
        return path

    def stop_recording(self, bake: bool, context=None, undo_step: bool = True) -> str | None:
        """Stop recording, keep the take, bake it when asked; the bake is one undo step (pushed here, or by
        finish() once the rig's pose is restored when `undo_step` is False)."""
        rec, self.recording = self.recording, None
        if rec is None:
            return None
        frames = self.session.recorder.frames if self.session.recorder else 0
        path = self.session.stop_recording()
        if rec["playing"] and context is not None and context.screen is not None \
                and context.screen.is_animation_playing:
            bpy.ops.screen.animation_cancel(restore_frame=False)
        if path is None:
            self.post("WARNING", "Recording stopped: no frame was recorded")
            return None
        self.post("INFO", f"Recorded {frames} frames to {path}")
        if bake and self._bake(path, rec) and undo_step:
            push_undo_step()
        return path

    def _bake(self, path: str, rec: dict) -> bool:
        obj = self.obj()
        if obj is None:
            self.post("WARNING", f"Recording kept in {path}; the armature is gone, nothing was baked")
            return False
        pipeline = self.session.pipeline
        n = pipeline.retargeter.scale_for(pipeline.source_leg)  # the root scale live used
        try:
            take = load_take(path)
            # the take's times count from when recording started (not from its first sample): anchor the
            # keys there, so the timeline (and audio played with it) lines up with what happened
            start = rec["frame_start"] + int(round(float(take.times[0]) * rec["fps"])) if take.frame_count else \
                rec["frame_start"]
            settings = replace(self.settings, fps=rec["fps"], frame_start=start, root_scale=n)
            result = bake_take(obj, take, preset=self.preset, overrides=self.overrides, settings=settings,
                               action_name=rec["name"], options=recording_bake_options(self.scene()),
                               report=lambda level, msg: self.post(next(iter(level)), msg))
        except (TakeError, ValueError) as exc:
            self.post("ERROR", f"Recording kept in {path} but could not be baked: {exc}")
            return False
        self.baked_action = result.action.name
        first, last = result.frame_range
        scene = self.scene()
        if scene is not None and last > scene.frame_end:
            scene.frame_end = last
        self.post("INFO", f"Baked the recording to action {result.action.name!r} (frames {first}-{last})")
        return True

    # -- calibration -----------------------------------------------------------------------------------------
    def calibrate(self, seconds: float = 1.0) -> None:
        self.message = "Calibrating: stand still in a T-pose or A-pose"
        self.session.start_calibration(self._calibrated, seconds)

    def _calibrated(self, capture) -> None:
        pipeline = self.session.pipeline
        obj = self.obj()
        try:
            cal = capture.result(self.session.source.skeleton, pipeline.retargeter.target_leg,
                                 pipeline.rig.generated)
        except CalibrationError as exc:
            self.post("ERROR", f"Calibration failed: {exc}")
            return
        pipeline.source_leg = cal.source_leg
        if obj is not None:
            obj[CALIBRATION_PROPERTY] = cal.to_json()  # saved with the .blend
        self.post("INFO", f"Calibrated ({cal.pose}): performer leg {cal.source_leg:.3f} m, "
                          f"root scale {cal.root_scale:.3f}")

    # -- stopping --------------------------------------------------------------------------------------------
    def bake_on_stop(self) -> bool:
        """The scene's *Bake on Stop*: every stop path that does not say otherwise follows it."""
        scene = self.scene()
        return bool(scene.kinect_retarget.bake_on_stop) if scene is not None else False

    def finish(self, bake: bool | None = None, context=None) -> None:
        """Every stop path ends here: thread, recording (kept; baked when asked, by default when the scene's
        Bake on Stop is on), pose, timer."""
        global _controller
        if bake is None:
            bake = self.bake_on_stop()
        session = self.session
        session.stop()
        self.release_evaluator()
        baked_before = self.baked_action
        if self.recording is not None:
            self.stop_recording(bake=bake, context=context, undo_step=False)
        obj = self.obj()
        if obj is not None:
            _restore_state(obj, self._saved, keep_animation=self.baked_action is not None)
        if self.baked_action != baked_before:
            push_undo_step()  # the Action, its assignment and the restored pose: one step
        if session.error:
            self.post("ERROR", f"Live stopped: {session.error}")
        elif not self.message.startswith("Baked"):
            self.message = "Live stopped"
        _last_status.update(state="error" if session.error else "idle", message=self.message,
                            error=session.error or _last_status.get("error"), stats=session.statistics())
        if _controller is self:
            _controller = None
        if bpy.app.timers.is_registered(_timer):
            bpy.app.timers.unregister(_timer)
        redraw_3d_views()


def _unused_path(folder: str, base: str, ext: str) -> tuple[str, str]:
    """A file name in `folder` that does not exist yet: `base`, else `base_2`, `base_3`... (two recordings
    started within one second must not overwrite each other). Returns the path and the suffix used."""
    suffix, n = "", 1
    while os.path.exists(os.path.join(folder, base + suffix + ext)):
        n += 1
        suffix = f"_{n}"
    return os.path.join(folder, base + suffix + ext), suffix


def _save_state(obj) -> dict:
    """What live changes on the rig, by name (undo during live invalidates bpy references)."""
    ad = obj.animation_data
    action = ad.action if ad else None
    state = {"pose": snapshot_pose(obj),
             "ik_fk": {n: obj.pose.bones[n]["IK_FK"] for n in fk_switch_bones(obj)},
             "action": action.name if action else None,
             "slot": ad.action_slot.identifier if action is not None and ad.action_slot else None,
             "fake_user": action.use_fake_user if action is not None else False}
    if action is not None:
        # unassigned while live (it would overwrite the live pose on every evaluation), but held by a fake
        # user so that saving during live, or a crash, does not drop it; the user's flag comes back on stop
        action.use_fake_user = True
        ad.action = None
    return state


def _restore_state(obj, state: dict, keep_animation: bool) -> None:
    for name, value in state["ik_fk"].items():
        if name in obj.pose.bones:
            obj.pose.bones[name]["IK_FK"] = value
    action = bpy.data.actions.get(state["action"]) if state["action"] else None
    if keep_animation:  # the baked recording now animates the rig
        if action is not None:
            action.use_fake_user = state.get("fake_user", False)
            if action.users == 0:
                action.use_fake_user = True  # the rig's previous action must not vanish on the next save
        return
    restore_pose(obj, state["pose"])
    if action is not None:
        ad = obj.animation_data or obj.animation_data_create()
        ad.action = action
        slot = next((sl for sl in action.slots if sl.identifier == state["slot"]), None)
        if slot is not None:
            ad.action_slot = slot
        action.use_fake_user = state.get("fake_user", False)


def redraw_3d_views() -> None:
    """Tag every 3D viewport for a redraw (live and the USB panel's depth preview)."""
    wm = getattr(bpy.context, "window_manager", None)
    if wm is None:
        return
    for window in wm.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def _timer():
    c = _controller
    if c is None:
        return None
    try:
        alive = c.pump()
    except Exception as exc:  # never let a timer die with live half-running
        c.session.stop(f"unexpected {type(exc).__name__}: {exc}")
        c.finish()
        alive = False
    if not alive:
        return None
    redraw_3d_views()
    return TIMER_INTERVAL


# -- the functions operators, the CLI and tests call ----------------------------------------------------------
def make_source(settings, prefs):
    if settings.source == "TAKE":
        if not settings.take_path:
            raise SourceError("choose a take file to play")
        return TakePlayback(bpy.path.abspath(settings.take_path), speed=settings.speed, loop=settings.loop), \
            f"take {os.path.basename(settings.take_path)}"
    if settings.source == "OSC":
        host, refused = osc_host(prefs)
        return OscReceiver(settings.osc_port, host=host), \
            f"OSC port {settings.osc_port}" + (" (this computer only: online access is off)" if refused else "")
    if usb_source_factory is not None:
        return usb_source_factory(settings, prefs)
    return UsbKinectSource(), "USB Kinect"


def start_live(context, source=None, use_timer: bool = True) -> LiveController:
    """Start live on the scene's target armature. Raises SourceError/ValueError with a user sentence."""
    global _controller
    if _controller is not None:
        raise SourceError("live is already running")
    scene = context.scene
    ensure_defaults(scene, context)
    s = scene.kinect_retarget
    obj = target_armature(context)
    if obj is None:
        raise ValueError("pick a target armature (or make one active) first")
    prefs = get_preferences(context)
    label = "custom source"
    if source is None:
        source, label = make_source(s, prefs)
    overrides = table_overrides(s)
    settings = RetargetSettings(filter=s.filter, root_mode=s.root, mirror=s.mirror)
    pipeline, used = make_pipeline(obj, source.skeleton, s.preset, overrides, settings)
    cal_text = obj.get(CALIBRATION_PROPERTY)
    if cal_text:
        try:
            cal = Calibration.from_json(cal_text)
            if cal.skeleton == source.skeleton.name:
                pipeline.source_leg = cal.source_leg
        except CalibrationError:
            pass  # a stale or foreign calibration: live still works, uncalibrated
    timeout = prefs.lost_tracking_timeout if prefs is not None else 2.0
    session = LiveSession(source, pipeline, lambda pose: None, lost_tracking_timeout=timeout)
    saved = _save_state(obj)
    try:
        controller = LiveController(scene, obj, session, used, overrides, settings, label, saved)
        session.apply = controller.apply
        session.start()
    except Exception:  # any failure: the rig gets its pose, action and switches back before the error goes up
        _restore_state(obj, saved, keep_animation=False)
        raise
    _controller = controller
    _last_status.update(state="running", message=controller.message, error=None, stats=None)
    if use_timer and not bpy.app.timers.is_registered(_timer):
        bpy.app.timers.register(_timer, first_interval=0.0)
    return controller


def pump_live() -> bool:
    """One main-thread step, for loops that block (the timer does the same)."""
    c = _controller
    return c.pump() if c is not None else False


def stop_live(bake: bool | None = None, context=None) -> None:
    """Stop live; `bake` None follows the scene's Bake on Stop."""
    if _controller is not None:
        _controller.finish(bake=bake, context=context)


def controller() -> LiveController | None:
    return _controller


def status() -> dict:
    """For the panel: state, message, error, fps, tracked joints, statistics."""
    c = _controller
    if c is None:
        return dict(_last_status)
    src = c.session.source
    return {"state": "recording" if c.recording else "running", "message": c.message,
            "error": src.error, "warning": src.warning, "stats": c.session.statistics(), "tracked": c.session.last_tracked_joints,
            "joints": len(src.skeleton), "calibrating": c.session.calibrating,
            "device": getattr(src, "device_status", None),
            "progress": (src.position + 1, src.take.frame_count) if isinstance(src, TakePlayback) else None,
            "recording": c.recording["path"] if c.recording else None}


def run_headless(source, seconds: float, *, rig_path=None, armature=None, preset="auto",
                 filter_name="default", root="xyz", mirror=False, overrides=None, record=None, out=None,
                 rig_lengths=None) -> dict:
    """The `live` command: open the rig (or build the generated one with `rig_lengths`), run the pump loop
    for `seconds` (or until the source ends), bake the recording, save `out`. Returns the statistics."""
    from ... import register, unregister
    from ..headless import blender_message, open_target, save_blend
    from ..io.kinect_rig import build_kinect_rig
    from ..ui.mapping_table import fill_table

    def generate(scene):
        obj = build_kinect_rig(scene, source.skeleton, rig_lengths, "KinectRig")
        set_scene_rate(scene, source.rate)  # a new scene runs at the source's rate, as `bake` sets it
        return obj

    obj, preset = open_target(rig_path, armature, preset, generate)
    register()   # once the rig is there: neither opening nor building it needs the add-on
    try:
        bpy.context.view_layer.objects.active = obj
        s = bpy.context.scene.kinect_retarget
        s.initialised = True
        s.armature, s.preset, s.filter, s.root, s.mirror = obj, preset, filter_name, root, mirror
        s.play_on_record = False
        # the command bakes what it records, also when the source ends first
        user_bake_on_stop, s.bake_on_stop = s.bake_on_stop, bool(record)
        if overrides:
            fill_table(s, overrides)
        try:
            c = start_live(bpy.context, source=source, use_timer=False)
        except SourceError as exc:
            raise ValueError(str(exc)) from None
        if record:
            try:
                c.start_recording(bpy.context, os.path.abspath(record))
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
        s.bake_on_stop = user_bake_on_stop  # the saved file keeps the user's setting
        result = {"seconds": round(elapsed, 3), "armature": obj.name, **c.session.statistics(),
                  "error": c.session.error, "record": os.path.abspath(record) if record else None,
                  "action": c.baked_action, "warning": source.warning}
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


# -- operators -----------------------------------------------------------------------------------------------
def _flush_reports(op, controller=None) -> None:
    """Pass a controller's queued reports to the operator (default: the running one; a stopped one's last
    words are passed explicitly)."""
    c = controller if controller is not None else _controller
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
        if _controller is not None:
            cls.poll_message_set("Live is already running")
            return False
        if target_armature(context) is None:
            cls.poll_message_set("Pick a target armature (or make one active)")
            return False
        return True

    def execute(self, context):
        try:
            self._ctrl = start_live(context)
        except (SourceError, ValueError, TakeError) as exc:
            _last_status.update(state="error", error=str(exc), message=str(exc))
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
        if event.type == "ESC" and event.value == "PRESS" and _controller is self._ctrl:
            _flush_reports(self)
            stop_live(context=context)
        if _controller is not self._ctrl or self._ctrl is None:
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
        return _controller is not None

    def execute(self, context):
        c = _controller
        stop_live(context=context)
        _flush_reports(self, c)
        return {"FINISHED"}


class KINECT_RETARGET_OT_record(bpy.types.Operator):
    """Start recording the live frames to a take, or stop and bake the recording onto the rig"""
    bl_idname = "kinect_retarget.record"
    bl_label = "Record"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        if _controller is None:
            cls.poll_message_set("Start live first")
            return False
        return True

    def execute(self, context):
        c = _controller
        try:
            if c.recording is None:
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
        if _controller is None:
            cls.poll_message_set("Start live first, then stand still in a T-pose or A-pose")
            return False
        return not _controller.session.calibrating

    def execute(self, context):
        _controller.calibrate(1.0)
        self.report({"INFO"}, "Calibrating: stand still for one second")
        return {"FINISHED"}


@persistent
def _on_save_pre(*_args) -> None:
    # the armature copy of Exact on Constrained Rigs must not be saved: it comes back on the next frame
    if _controller is not None:
        _controller.release_evaluator()


@persistent
def _on_load_pre(*_args) -> None:
    # the scene is about to be replaced: end the thread, keep the recording file, bake nothing
    stop_live(bake=False)


def register_extra() -> None:
    if _on_load_pre not in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.append(_on_load_pre)
    if _on_save_pre not in bpy.app.handlers.save_pre:
        bpy.app.handlers.save_pre.append(_on_save_pre)


def unregister_extra() -> None:
    stop_live(bake=False)
    if _on_load_pre in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(_on_load_pre)
    if _on_save_pre in bpy.app.handlers.save_pre:
        bpy.app.handlers.save_pre.remove(_on_save_pre)
    if bpy.app.timers.is_registered(_timer):
        bpy.app.timers.unregister(_timer)


CLASSES = (KINECT_RETARGET_OT_live_start, KINECT_RETARGET_OT_live_stop, KINECT_RETARGET_OT_record,
           KINECT_RETARGET_OT_calibrate)
