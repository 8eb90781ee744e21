"""The live controller (main thread only): one live run on one rig. It owns the bpy-free LiveSession (drain,
filter, retarget, record), poses the rig with the newest frame, records, bakes the recording, calibrates, and
puts the rig back when it stops. Live pushes no undo steps and holds object names, never bpy references.
Starting, pumping and stopping the one running controller is live_runtime.py's job. With several performers
(one source's bodies, sources/body_fanout.py) the running controller leads `followers`, one controller per
other rig: they start, pump, record, bake, calibrate and stop with it.
"""
from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field, replace
from typing import Callable

import bpy
import numpy as np

from ...core.parent_fit import relative_to_parent
from ...core.performer_calibration import PROPERTY as CALIBRATION_PROPERTY, Calibration, CalibrationError
from ...core.pipeline import RetargetSettings
from ...core.take import TakeError
from ...live.recording import unused_path
from ...live.session import LiveSession
from ...sources import SourceError
from ...takes import load_take
from ..bake_take import bake_take, make_pipeline
from ..io.armature_probe import ArmatureEvaluator, constrained_summary, probe_parents, read_rotations, solve_frames
from ..io.finger_rig import hands_on_rig, pose_with_hands
from ..io.pose_apply import apply_frame_pose
from ..io.rig_reader import fk_switch_bones, has_constrained_ancestry
from ..ui.bake_settings import recording_bake_options
from ..ui.takes_list import add_take
from . import record_countdown
from .rig_state import restore_rig_state, save_rig_state, switch_limbs_to_fk
from .undo_step import push_undo_step


@dataclass
class LiveSettings:
    """What live needs besides the rig, the source and the mapping overrides. The sidebar builds it from the
    scene (live_runtime.settings_from_scene), the `live` command from its arguments."""
    preset: str = "auto"
    retarget: RetargetSettings = field(default_factory=RetargetSettings)
    exact_constrained: bool = False     # fallback bones of constrained rigs evaluated on an armature copy
    bake_on_stop: bool | None = None    # None: the scene's Bake on Stop toggle at the moment live stops
    lost_tracking_timeout: float = 2.0
    hands: str = "auto"                 # Kinect v2 hands on rigs with finger bones (auto: v2 sources)


def _apply_saved_calibration(obj, source, pipeline) -> None:
    cal_text = obj.get(CALIBRATION_PROPERTY)
    if not cal_text:
        return
    try:
        cal = Calibration.from_json(cal_text)
    except CalibrationError:
        return  # a stale or foreign calibration: live still works, uncalibrated
    if cal.skeleton == source.skeleton.name:
        pipeline.source_leg = cal.source_leg


class LiveController:
    def __init__(self, scene, obj, source, settings: LiveSettings, overrides, source_label: str,
                 on_finish: Callable[["LiveController"], None] | None = None):
        """Builds the pipeline and the session; `start()` saves the rig's state and starts the source."""
        self.scene_name, self.obj_name = scene.name, obj.name
        pipeline, self.preset = make_pipeline(obj, source.skeleton, settings.preset, overrides, settings.retarget)
        _apply_saved_calibration(obj, source, pipeline)
        self.session = LiveSession(source, pipeline, self.apply,
                                   lost_tracking_timeout=settings.lost_tracking_timeout)
        self.overrides, self.settings, self.live_settings = overrides, settings.retarget, settings
        self.source_label = source_label
        self.on_finish = on_finish
        self.reports: list[tuple[str, str]] = []
        self.message = f"Live: {source_label} -> {obj.name}"
        self.last_error: str | None = None
        self.recording: dict | None = None
        self.baked_action: str | None = None
        self.started_at = time.perf_counter()
        self._saved: dict | None = None   # the rig's pose, action and switches before live: put back by finish()
        self._switches = {name: 1.0 for name in fk_switch_bones(obj)}   # live drives FK; the copy is set the same
        self.model = None       # learned constrained parents (issue 15): exact live poses in numpy
        self.evaluator = None   # the armature copy for Exact on Constrained Rigs, only with fallback bones
        self.update_after_apply = False
        self.exact = False
        joints = source.skeleton.joints
        wanted = settings.hands == "on" or (settings.hands == "auto" and "HandTipLeft" in joints)
        self.hands = hands_on_rig(obj, pipeline.retargeter.mapped) if wanted else []
        self._joints = joints
        self.body = int(getattr(source, "body", 0))
        self.followers: list[LiveController] = []
        self.finished = False

    def start(self) -> None:
        """Start this rig, then its followers; when one fails, those started stop and the error goes up."""
        self._start_one()
        started = []
        try:
            for f in self.followers:
                f._start_one()
                started.append(f)
        except Exception:
            for f in started + [self]:
                f.session.stop()
                f.release_evaluator()
                restore_rig_state(f.obj(), f._saved, keep_animation=False)
            raise

    def _start_one(self) -> None:
        """Save the rig's state, switch Rigify limbs to FK, learn its constrained parents, start the source; on
        any failure the rig gets its pose, action and switches back before the error goes up."""
        obj = self.obj()
        self._saved = save_rig_state(obj)
        try:
            switch_limbs_to_fk(obj)
            self._learn_constrained_parents(obj)
            self.session.start()
        except Exception:
            self.release_evaluator()
            restore_rig_state(obj, self._saved, keep_animation=False)
            raise

    def _learn_constrained_parents(self, obj) -> None:
        pipeline = self.session.pipeline
        if has_constrained_ancestry(obj, pipeline.bone_names):
            with ArmatureEvaluator(obj, pipeline.rig.bone_names, self._switches) as evaluator:
                self.model = probe_parents(evaluator, obj, pipeline.rig, pipeline.bone_names, pipeline.root_bone)
            self.reports.append(("WARNING" if self.model.fallback else "INFO", constrained_summary(self.model)))
        fallback = self.model is not None and bool(self.model.fallback)
        self.update_after_apply = bool(bpy.app.background) and fallback
        # exact costs Blender evaluations, so it is asked for only where a bone has no learned relation
        self.exact = self.live_settings.exact_constrained and fallback

    # -- helpers -------------------------------------------------------------------------------------------
    def obj(self):
        return bpy.data.objects.get(self.obj_name)

    def scene(self):
        return bpy.data.scenes.get(self.scene_name)

    def post(self, level: str, message: str) -> None:
        """For report(): the modal operator passes these on; the panel shows the last one."""
        self.reports.append((level, message))
        if level == "ERROR":
            self.last_error = message
        self.message = message
        print(f"kinect_retarget: {message}", file=sys.stderr)

    def apply(self, pose) -> None:
        obj = self.obj()
        if obj is None:
            raise RuntimeError(f"armature {self.obj_name!r} no longer exists")
        model = self.model
        if model is not None:
            if self.exact:  # fallback bones evaluated on the armature copy until they settle
                if self.evaluator is None:
                    self.evaluator = ArmatureEvaluator(obj, model.rig.bone_names, self._switches)
                scene = self.scene()  # drivers on animated properties: evaluate at the frame shown
                pose.quats = solve_frames(self.evaluator, model, pose.desired[None], pose.root_bone,
                                          pose.root_location[None], [scene.frame_current] if scene else None)[0]
            else:  # fallback bones (if any) as the viewport last evaluated them: one frame late
                pose.quats = model.solve(pose.desired[None], self._evaluated(obj) if model.fallback else None)[0]
        apply_frame_pose(obj, pose_with_hands(pose, self.hands, self._joints))
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
        for f in self.followers:
            if not f.finished and not f.session.pump():
                f.finish()
        if not alive:
            self.finish()
        return alive

    # -- recording ---------------------------------------------------------------------------------------------
    def start_recording(self, context, path: str | None = None, play: bool | None = None) -> str:
        """Record to `path`, or to a new file in the scene's recordings folder; `play` (default: the scene's
        Play on Record) starts the timeline when there is a screen to play it in."""
        scene = self.scene()
        s = getattr(scene, "kinect_retarget", None)
        stamp = time.strftime("%Y%m%d_%H%M%S")
        if path is None:
            folder = bpy.path.abspath((s.record_dir if s is not None else "") or "//kinect_takes/")
            if folder.startswith("//") or not os.path.isabs(folder):  # unsaved file: // has no meaning
                folder = os.path.join(bpy.app.tempdir or os.path.expanduser("~"), "kinect_takes")
            path, suffix = unused_path(folder, f"{bpy.path.clean_name(self.obj_name)}_{stamp}", ".krtake")
            stamp += suffix  # the action is named like its file
        name = f"{self.obj_name}_live_{stamp}"
        for f in self.followers:  # each performer to its own file, beside this one when a path was given
            if f.session.running:
                base, ext = os.path.splitext(path) if path is not None else (None, None)
                f.start_recording(None, f"{base}_body{f.body}{ext}" if base is not None else None, play=False)
        try:
            self.session.start_recording(path, {"name": name, "armature": self.obj_name,
                                                "source": self.source_label})
        except OSError as exc:
            raise SourceError(f"cannot write the recording {path}: {exc.strerror or exc}") from None
        fps = scene.render.fps / scene.render.fps_base
        self.recording = {"path": path, "name": name, "frame_start": scene.frame_current, "fps": fps,
                          "playing": False}
        if play is None:
            play = bool(s.play_on_record) if s is not None else False
        if play and context is not None and context.screen is not None \
                and not context.screen.is_animation_playing:
            bpy.ops.screen.animation_play()
            self.recording["playing"] = True
        self.message = f"Recording to {path}"
        return path

    def stop_recording(self, bake: bool, context=None, undo_step: bool = True) -> str | None:
        """Stop recording, keep the take, bake it when asked; the bake is one undo step (pushed here, or by
        finish() once the rig's pose is restored when `undo_step` is False)."""
        for f in self.followers:
            f.stop_recording(bake, context, undo_step)
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
        if self.scene() is not None:
            add_take(self.scene(), path)
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
        for f in self.followers:
            f.calibrate(seconds)
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
        """Every stop path that does not say otherwise follows this: the settings' choice, else the scene's
        *Bake on Stop* toggle as it is now (the user may flip it while live runs)."""
        if self.live_settings.bake_on_stop is not None:
            return self.live_settings.bake_on_stop
        scene = self.scene()
        s = getattr(scene, "kinect_retarget", None) if scene is not None else None
        return bool(s.bake_on_stop) if s is not None else False

    def finish(self, bake: bool | None = None, context=None) -> None:
        """Every stop path ends here: thread, recording (kept; baked when asked, by default when the scene's
        Bake on Stop is on), pose, timer."""
        if bake is None:
            bake = self.bake_on_stop()
        for f in self.followers:  # before this rig's own source view: the last view stops the shared source
            if not f.finished:
                f.finish(bake=bake, context=context)
        session = self.session
        session.stop()
        record_countdown.cancel()  # stopping live calls off a recording not yet started
        self.release_evaluator()
        baked_before = self.baked_action
        if self.recording is not None:
            self.stop_recording(bake=bake, context=context, undo_step=False)
        obj = self.obj()
        if obj is not None and self._saved is not None:
            restore_rig_state(obj, self._saved, keep_animation=self.baked_action is not None)
        if self.baked_action != baked_before:
            push_undo_step()  # the Action, its assignment and the restored pose: one step
        if session.error:
            self.post("ERROR", f"Live stopped: {session.error}")
        elif not self.message.startswith("Baked"):
            self.message = "Live stopped"
        self.finished = True
        if self.on_finish is not None:
            self.on_finish(self)
