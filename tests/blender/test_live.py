"""Live in Blender, headless: the same pump the timer runs, on a real armature (bpy 5.0.1 wheel)."""
from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import bpy
import numpy as np
import pytest

import kinect_retarget
from kinect_retarget.blender.live import live_runtime as live
from kinect_retarget.blender.io.kinect_rig import build_kinect_rig
from kinect_retarget.core.kinect_rig_layout import median_segment_lengths
from kinect_retarget.core.quat import angle_between
from kinect_retarget.core.skeletons import KINECT_V2
from kinect_retarget.core.take import Take
from kinect_retarget.core.performer_calibration import PROPERTY as CALIBRATION
from kinect_retarget.sources import TakePlayback
from kinect_retarget.sources.frame_source import FrameSource
from kinect_retarget.takes import kinect_v2_csv, krtake

REPO_SAMPLE = Path(__file__).resolve().parents[2] / "sample_takes" / "kinect_v2_ges03_drawlines.krtake"


def _csv_take(path, frames=None) -> Take:
    """The KinectReader CSV through the package's reader, cut to `frames`, positions at .krtake precision."""
    take = kinect_v2_csv.read(path)
    n = frames or take.frame_count
    return Take(take.skeleton, np.round(take.positions[:n], 5), take.states[:n], take.times[:n], take.rate)


@pytest.fixture
def registered():
    kinect_retarget.register()
    yield
    live.stop_live(bake=False)
    kinect_retarget.unregister()


@pytest.fixture
def scene_with_rig(registered, data_dir, tmp_path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    take = _csv_take(data_dir / "kinect_v2" / "Ges01_wavehand.csv", frames=90)
    path = tmp_path / "wave.krtake"
    krtake.write(path, take)
    scene = bpy.context.scene
    obj = build_kinect_rig(scene, KINECT_V2, median_segment_lengths(take), "KinectRig")
    bpy.context.view_layer.objects.active = obj
    s = scene.kinect_retarget
    s.initialised = True
    s.source, s.take_path, s.speed, s.loop = "TAKE", str(path), 3.0, False
    s.armature = obj
    s.record_dir = str(tmp_path / "rec")
    s.play_on_record = False
    return scene, obj, take, path


def wait_for(cond, seconds=60.0, pump=True) -> bool:
    """Pump until `cond()` holds; the deadline is generous because the machine may be loaded."""
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        if pump:
            live.pump_live()
        if cond():
            return True
        time.sleep(0.003)
    return cond()


class LockstepPlayback(TakePlayback):
    """Hands over the next frame only once the pump has drained the last, so every frame is shown
    however loaded the machine is (a fixed count of pumps would depend on timing)."""

    def _emit(self, *args, **kwargs):
        super()._emit(*args, **kwargs)
        while len(self._queue) and not self.stopping:
            time.sleep(0.001)


def run_live(seconds=60.0):
    end = time.perf_counter() + seconds
    while live.pump_live() and time.perf_counter() < end:
        time.sleep(0.003)


def pose_quats(obj, names):
    return np.array([obj.pose.bones[n].rotation_quaternion[:] for n in names])


def test_live_poses_rig_records_and_bakes_at_timeline_frames(scene_with_rig):
    scene, obj, take, _ = scene_with_rig
    scene.frame_current = 40
    rest = pose_quats(obj, [b.name for b in obj.pose.bones])
    seen = []
    c = live.start_live(bpy.context, source=LockstepPlayback(take, speed=3.0), use_timer=False)
    apply = c.session.apply
    c.session.apply = lambda pose: (apply(pose), seen.append((pose, pose_quats(obj, pose.bone_names))))
    c.start_recording(bpy.context)
    rec_path = c.recording["path"]
    run_live()
    assert live.controller() is None, "a non-looping take ends live by itself"
    st = live.status()
    assert st["error"] is None and st["stats"]["received"] == take.frame_count == st["stats"]["recorded"]
    assert len(seen) >= 5  # lockstep: nothing superseded; only a pump later than `stale_after` hides one
    # the applied values are what Blender holds (float32)
    pose, held = seen[-1]
    assert np.degrees(angle_between(held, pose.quats)).max() < 1e-3
    assert not np.allclose(held, rest[: len(held)])
    # recording kept and baked: keys from the frame where recording started, at the scene rate
    assert os.path.isfile(rec_path) and krtake.read(rec_path).frame_count == take.frame_count
    action = obj.animation_data.action
    assert action is not None and action.name.startswith("KinectRig_live_")
    fc = action.layers[0].strips[0].channelbag(action.slots[0]).fcurves
    curve = fc.find('pose.bones["SpineMid"].rotation_quaternion', index=0)
    keys = np.array([k.co[0] for k in curve.keyframe_points])
    rec = krtake.read(rec_path)
    fps = scene.render.fps / scene.render.fps_base
    assert keys[0] == 40 + round(rec.times[0] * fps)  # anchored where recording started
    assert keys[-1] == keys[0] + round((rec.times[-1] - rec.times[0]) * fps)
    # live equals baked: each applied pose is the action's value at that sample's frame
    names = seen[0][0].bone_names
    for pose, held in seen[:: max(1, len(seen) // 8)]:
        i = int(np.argmin(np.abs(rec.times - pose.time)))
        frame = int(keys[0]) + round((rec.times[i] - rec.times[0]) * fps)
        if i and frame == keys[0] + round((rec.times[i - 1] - rec.times[0]) * fps):
            continue  # another sample owns this frame's key
        scene.frame_set(frame)
        assert np.degrees(angle_between(pose_quats(obj, names), pose.quats)).max() < 1e-3


def test_stop_without_recording_restores_the_pose(scene_with_rig):
    scene, obj, take, _ = scene_with_rig
    obj.pose.bones["ElbowLeft"].rotation_quaternion = (0.9, 0.1, 0.3, 0.0)
    before = pose_quats(obj, [b.name for b in obj.pose.bones])
    scene.kinect_retarget.loop = True
    live.start_live(bpy.context, use_timer=False)
    assert wait_for(lambda: not np.allclose(pose_quats(obj, [b.name for b in obj.pose.bones]), before, atol=1e-4))
    st = live.status()  # what the panel draws
    assert st["state"] == "running" and st["progress"][1] == take.frame_count and st["joints"] == 25
    assert st["tracked"] > 0 and st["stats"]["applied"] > 0
    bpy.ops.kinect_retarget.live_stop()
    assert live.controller() is None
    np.testing.assert_allclose(pose_quats(obj, [b.name for b in obj.pose.bones]), before, atol=1e-6)
    assert obj.animation_data is None or obj.animation_data.action is None
    assert not [t for t in threading.enumerate() if t.name.startswith("kinect_retarget")]


def test_file_vanishing_shows_error_stops_and_keeps_recording(scene_with_rig):
    scene, obj, take, path = scene_with_rig
    scene.kinect_retarget.speed = 1.0
    c = live.start_live(bpy.context, use_timer=False)
    c.start_recording(bpy.context)
    rec_path = c.recording["path"]
    assert wait_for(lambda: c.session.stats.recorded >= 5)
    os.remove(path)
    run_live()
    st = live.status()
    assert st["state"] == "error" and "vanished" in st["error"] and str(path) in st["error"]
    kept = krtake.read(rec_path)
    assert kept.frame_count >= 5
    assert obj.animation_data.action is not None  # what was recorded got baked too
    assert not [t for t in threading.enumerate() if t.name.startswith("kinect_retarget") and t.is_alive()]


class _Scripted(FrameSource):
    kind = "scripted"

    def __init__(self, take, nan_at=None, untracked_from=None):
        super().__init__(take.skeleton, 30.0)
        self.take, self.nan_at, self.untracked_from = take, nan_at, untracked_from

    def _run(self):
        for i in range(self.take.frame_count):
            if not self._sleep(0.004):
                return
            pos, st = self.take.positions[i].copy(), self.take.states[i].copy()
            if i == self.nan_at:
                pos[5] = np.nan
            if self.untracked_from is not None and i >= self.untracked_from:
                st[:] = 0
            self._emit(pos, st, i / 30.0, where=f" frame {i}")


@pytest.mark.parametrize("fault, expect", [({"nan_at": 25}, "NaN"), ({"untracked_from": 20}, "no tracked joints")])
def test_bad_frames_stop_live_with_the_reason(scene_with_rig, fault, expect):
    scene, obj, take, _ = scene_with_rig
    bpy.context.preferences.addons  # preferences may be absent when registered as a plain module
    c = live.start_live(bpy.context, source=_Scripted(take, **fault), use_timer=False)
    c.session.lost_tracking_timeout = 0.3
    c.start_recording(bpy.context)
    rec_path = c.recording["path"]
    run_live()
    st = live.status()
    assert st["state"] == "error" and expect in st["error"]
    assert krtake.read(rec_path).frame_count >= 20


def test_calibration_is_stored_on_the_rig_and_survives_save_and_load(scene_with_rig, tmp_path):
    scene, obj, take, _ = scene_with_rig
    scene.kinect_retarget.loop = True
    c = live.start_live(bpy.context, use_timer=False)
    c.calibrate(0.15)
    end = time.perf_counter() + 5
    while c.session.calibrating and time.perf_counter() < end:
        live.pump_live()
        time.sleep(0.005)
    live.stop_live(bake=False)
    stored = obj.get(CALIBRATION)
    assert stored and '"root_scale": 1.0' in stored  # the generated rig keeps n = 1
    blend = str(tmp_path / "cal.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=blend)
    assert bpy.data.objects["KinectRig"].get(CALIBRATION) == stored


def test_loading_a_file_stops_live(scene_with_rig, tmp_path):
    scene, obj, take, _ = scene_with_rig
    scene.kinect_retarget.loop = True
    blend = str(tmp_path / "other.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    live.start_live(bpy.context, use_timer=True)
    live.pump_live()
    bpy.ops.wm.open_mainfile(filepath=blend)
    assert live.controller() is None
    assert not bpy.app.timers.is_registered(live._timer)
    assert not [t for t in threading.enumerate() if t.name.startswith("kinect_retarget") and t.is_alive()]


def test_live_operators_push_no_undo_steps_and_show_in_search(registered):
    from kinect_retarget.blender.ui.live_operators import CLASSES
    for cls in CLASSES:
        assert "UNDO" not in cls.bl_options, cls.bl_idname
        assert cls.bl_idname.startswith("kinect_retarget.") and cls.__doc__  # F3 search shows label + tooltip
        assert "INTERNAL" not in cls.bl_options
        assert getattr(bpy.ops.kinect_retarget, cls.bl_idname.split(".")[1]).get_rna_type() is not None


class _Manual(FrameSource):
    """Frames pushed by the test itself (the thread only idles), so each pump sees exactly one frame."""
    kind = "manual"

    def _run(self):
        while self._sleep(0.05):
            pass


def _mapped_error(obj, names, desired) -> float:
    """Worst degrees between the mapped bones' rotations as Blender evaluated them and the desired ones."""
    from kinect_retarget.core.quat import from_matrix
    act = np.array([np.array(obj.pose.bones[n].matrix)[:3, :3] for n in names])
    act /= np.linalg.norm(act, axis=-2, keepdims=True)
    return float(np.degrees(angle_between(from_matrix(act), desired)).max())


def _live_error_while_moving(obj, c, src, take, frames) -> list[float]:
    wanted = []
    apply = c.session.apply
    c.session.apply = lambda pose: (wanted.append(pose.desired.copy()), apply(pose))
    names = c.session.pipeline.bone_names
    moving = []
    for f in frames:
        src._emit(take.positions[f], take.states[f], f / 30)
        live.pump_live()
        bpy.context.view_layer.update()  # what the viewport's redraw does
        moving.append(_mapped_error(obj, names, wanted[-1]))
    return moving


@pytest.mark.parametrize("renamed", [False, True], ids=["rigify", "renamed-structure"])
def test_live_on_rigify_is_exact_while_moving(registered, rigify_rig_path, renamed):
    """Rigify's FK controls hang from constrained MCH bones: live uses the relations the probe learned at
    start, so every live pose is exact from the first frame, moving or not, without evaluating Blender. So
    it is with every bone renamed, mapped by structure (the limbs switched to FK through their drivers)."""
    from kinect_retarget.takes import load_take
    from tests.rigs.control_rigs import rename_bones

    bpy.ops.wm.open_mainfile(filepath=str(rigify_rig_path))
    obj = bpy.data.objects["rig"]
    back = rename_bones(obj, 12) if renamed else {}
    take = load_take(REPO_SAMPLE)
    s = bpy.context.scene.kinect_retarget
    s.initialised, s.armature, s.preset, s.filter = True, obj, "auto" if renamed else "rigify", "none"
    s.hands = "off"  # the hands roll the hand bones off the retarget's desired rotation on purpose (test_hands)
    src = _Manual(take.skeleton, 30.0)
    scenes = len(bpy.data.scenes)
    c = live.start_live(bpy.context, source=src, use_timer=False)
    assert c.model is not None and c.model.fallback == () and not c.exact and not c.update_after_apply
    assert len(bpy.data.scenes) == scenes   # the probe's armature copy and its scene are gone
    if renamed:
        assert {back[b] for b in c.session.pipeline.bone_names} >= {"torso", "chest", "upper_arm_fk.L", "shin_fk.R"}
        switches = [b for b, old in back.items() if old in ("upper_arm_parent.L", "thigh_parent.R")]
        assert [obj.pose.bones[b]["IK_FK"] for b in switches] == [1.0, 1.0]   # switched to FK while live
    moving = _live_error_while_moving(obj, c, src, take, range(61, 121))
    live.stop_live(bake=False)
    assert len(moving) == 60 and max(moving) < 0.001


def test_exact_live_on_a_rig_with_fallback_bones(registered, tmp_path):
    """A parent no relation explains (a Damped Track to an empty) is read from the last evaluation, one frame
    late; with "Exact on Constrained Rigs" it is evaluated on the armature copy every frame, so live is exact."""
    from .conftest import add_unlearnable_parents
    from kinect_retarget.takes import load_take

    take = load_take(REPO_SAMPLE)
    obj = build_kinect_rig(bpy.context.scene, take.skeleton, median_segment_lengths(take), "KinectRig")
    add_unlearnable_parents(bpy, obj, (1, 2))
    s = bpy.context.scene.kinect_retarget
    s.initialised, s.armature, s.preset, s.filter, s.exact_constrained = True, obj, "kinect", "none", True
    src = _Manual(take.skeleton, 30.0)
    c = live.start_live(bpy.context, source=src, use_timer=False)
    assert "MCH-aim" in c.model.fallback_names and c.exact
    moving = _live_error_while_moving(obj, c, src, take, range(61, 91))
    assert c.evaluator is not None
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "during_live.blend"), copy=True)
    assert c.evaluator is None and len(bpy.data.scenes) == 1   # the armature copy is never saved
    moving += _live_error_while_moving(obj, c, src, take, range(91, 95))
    live.stop_live(bake=False)
    assert c.evaluator is None and [sc.name for sc in bpy.data.scenes] == [bpy.context.scene.name]
    assert max(moving) < 0.001


def test_fallback_bones_without_exact_follow_one_frame_late(registered):
    """Without the Exact option a fallback parent is read from the last evaluation: a held pose is exact
    once the rig has been evaluated with it, and no armature copy is kept."""
    from .conftest import add_unlearnable_parents
    from kinect_retarget.takes import load_take

    take = load_take(REPO_SAMPLE)
    obj = build_kinect_rig(bpy.context.scene, take.skeleton, median_segment_lengths(take), "KinectRig")
    add_unlearnable_parents(bpy, obj, (1, 2))
    s = bpy.context.scene.kinect_retarget
    s.initialised, s.armature, s.preset, s.filter, s.exact_constrained = True, obj, "kinect", "none", False
    src = _Manual(take.skeleton, 30.0)
    c = live.start_live(bpy.context, source=src, use_timer=False)
    assert c.model.fallback and not c.exact
    held = _live_error_while_moving(obj, c, src, take, [60] * 3)  # the same frame three times
    assert c.evaluator is None and len(bpy.data.scenes) == 1
    live.stop_live(bake=False)
    assert held[-1] < 0.001


def test_mapping_table_save_load_and_disabled_rows_drive_nothing(scene_with_rig, tmp_path):
    scene, obj, take, _ = scene_with_rig
    s = scene.kinect_retarget
    s.preset = "kinect"
    assert bpy.ops.kinect_retarget.mapping_from_preset() == {"FINISHED"}
    assert len(s.mapping) == len(obj.data.bones)
    row = next(r for r in s.mapping if r.bone == "ElbowLeft")
    row.enabled = False
    path = str(tmp_path / "map.json")
    assert bpy.ops.kinect_retarget.mapping_save(filepath=path) == {"FINISHED"}
    bpy.ops.kinect_retarget.mapping_clear()
    assert len(s.mapping) == 0
    assert bpy.ops.kinect_retarget.mapping_load(filepath=path) == {"FINISHED"}
    assert {r.bone: (r.joint, r.enabled) for r in s.mapping}["ElbowLeft"] == ("", False)
    c = live.start_live(bpy.context, use_timer=False)
    assert "ElbowLeft" not in c.session.pipeline.bone_names and "ElbowRight" in c.session.pipeline.bone_names
    live.stop_live(bake=False)
    bad = tmp_path / "bad.json"
    bad.write_text("[1, 2")
    with pytest.raises(RuntimeError, match="cannot read bone mapping"):  # the ERROR report, file named
        bpy.ops.kinect_retarget.mapping_load(filepath=str(bad))
    assert len(s.mapping) == len(obj.data.bones)  # the table is untouched


def test_start_live_operator_reports_a_missing_take_and_leaves_nothing_running(scene_with_rig, tmp_path):
    scene, obj, take, _ = scene_with_rig
    scene.kinect_retarget.take_path = str(tmp_path / "gone.krtake")
    with pytest.raises(RuntimeError, match="does not exist"):  # bpy.ops raises the operator's ERROR report
        bpy.ops.kinect_retarget.live_start()
    assert live.controller() is None and "does not exist" in live.status()["error"]
    assert not bpy.app.timers.is_registered(live._timer)


def test_sidebar_tab_and_preferences_are_registered(registered):
    assert bpy.types.KINECT_RETARGET_PT_main.bl_category == "Kinect"
    assert bpy.types.KINECT_RETARGET_PT_main.bl_space_type == "VIEW_3D"
    from kinect_retarget.blender.ui.preferences import ADDON_ID, KinectRetargetPreferences
    assert KinectRetargetPreferences.bl_idname == ADDON_ID == "kinect_retarget"


def test_rig_action_is_detached_during_live_and_kept_safe(scene_with_rig):
    scene, obj, take, _ = scene_with_rig
    from kinect_retarget.blender.bake_take import bake_take
    bake_take(obj, take, preset="kinect", action_name="UserAction")
    user_action = obj.animation_data.action
    slot = obj.animation_data.action_slot.identifier
    # stop without recording: the user's action comes back with its slot
    live.start_live(bpy.context, use_timer=False)
    assert obj.animation_data.action is None
    live.pump_live()
    live.stop_live()
    assert obj.animation_data.action == user_action and obj.animation_data.action_slot.identifier == slot
    # a baked recording replaces it, and the previous action survives a save (fake user)
    c = live.start_live(bpy.context, use_timer=False)
    c.start_recording(bpy.context)
    run_live()
    assert obj.animation_data.action.name.startswith("KinectRig_live_")
    assert bpy.data.actions["UserAction"].use_fake_user


@pytest.mark.parametrize("fault", ["garbage", "socket"])
def test_osc_faults_reach_the_panel_status(scene_with_rig, fault):
    """Garbage is shown and skipped (live goes on); a socket error stops live with the reason."""
    import socket

    from kinect_retarget.sources import OscReceiver
    from kinect_retarget.sources.osc_codec import encode_message

    scene, obj, take, _ = scene_with_rig
    src = OscReceiver(port=0)
    c = live.start_live(bpy.context, source=src, use_timer=False)
    c.start_recording(bpy.context)
    rec_path = c.recording["path"]

    def send_frame(s, i):
        for j, name in enumerate(take.skeleton.joints):
            s.sendto(encode_message("/" + name, *map(float, take.positions[i, j])), ("127.0.0.1", src.port))
        s.sendto(encode_message("/NI_mate_sync", "x"), ("127.0.0.1", src.port))

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for i in range(3):
            send_frame(s, i)
        assert wait_for(lambda: c.session.stats.recorded == 3)
        if fault == "garbage":
            s.sendto(b"\x00\x01not osc", ("127.0.0.1", src.port))
            assert wait_for(lambda: live.status().get("warning"))
            st = live.status()
            assert st["state"] == "recording" and st["error"] is None and "bad OSC packet" in st["warning"]
            send_frame(s, 3)
            assert wait_for(lambda: c.session.stats.recorded == 4)
            live.stop_live(bake=False)
            assert krtake.read(rec_path).frame_count == 4
        else:
            src._sock.close()
            run_live(5.0)
            st = live.status()
            assert st["state"] == "error" and "socket error" in st["error"]
            assert krtake.read(rec_path).frame_count == 3
    assert not [t for t in threading.enumerate() if t.name.startswith("kinect_retarget") and t.is_alive()]


def test_invoke_without_a_window_runs_on_the_timer(scene_with_rig):
    scene, obj, take, _ = scene_with_rig
    scene.kinect_retarget.loop = True
    assert bpy.ops.kinect_retarget.live_start("INVOKE_DEFAULT") == {"FINISHED"}
    assert live.controller() is not None and bpy.app.timers.is_registered(live._timer)
    assert bpy.ops.kinect_retarget.live_stop() == {"FINISHED"}
    assert live.controller() is None and not bpy.app.timers.is_registered(live._timer)


def test_a_source_failing_with_any_exception_restores_the_rig(scene_with_rig):
    scene, obj, take, _ = scene_with_rig
    user_action = bpy.data.actions.new("UserAction")
    obj.animation_data_create().action = user_action
    obj.pose.bones["ElbowLeft"].rotation_quaternion = (0.9, 0.1, 0.3, 0.0)
    before = pose_quats(obj, [b.name for b in obj.pose.bones])

    class Broken(FrameSource):
        kind = "broken"

        def _open(self):
            raise RuntimeError("driver crashed")

    with pytest.raises(RuntimeError, match="driver crashed"):
        live.start_live(bpy.context, source=Broken(take.skeleton, 30.0), use_timer=False)
    assert live.controller() is None
    assert obj.animation_data.action == user_action
    np.testing.assert_allclose(pose_quats(obj, [b.name for b in obj.pose.bones]), before, atol=1e-6)


@pytest.mark.parametrize("how", ["take_ends", "stop_operator", "source_error"])
def test_bake_on_stop_off_keeps_the_recording_unbaked_on_every_stop_path(scene_with_rig, how):
    scene, obj, take, path = scene_with_rig
    scene.kinect_retarget.bake_on_stop = False
    scene.kinect_retarget.loop = how != "take_ends"
    c = live.start_live(bpy.context, use_timer=False)
    c.start_recording(bpy.context)
    rec_path = c.recording["path"]
    assert wait_for(lambda: c.session.stats.recorded >= 5)
    if how == "stop_operator":
        assert bpy.ops.kinect_retarget.live_stop() == {"FINISHED"}
    elif how == "source_error":
        os.remove(path)  # the looping reader notices within 30 frames
        run_live()
        assert "vanished" in live.status()["error"]
    else:
        run_live()
    assert live.controller() is None
    assert krtake.read(rec_path).frame_count >= 5
    assert c.baked_action is None and (obj.animation_data is None or obj.animation_data.action is None)


def test_recordings_started_in_the_same_second_get_their_own_files(scene_with_rig, monkeypatch):
    scene, obj, take, _ = scene_with_rig
    scene.kinect_retarget.loop = True
    scene.kinect_retarget.bake_on_stop = False
    from kinect_retarget.blender.live import live_controller
    monkeypatch.setattr(live_controller.time, "strftime", lambda fmt: "20260101_120000")  # one second for all three
    c = live.start_live(bpy.context, use_timer=False)
    paths, counts = [], []
    for _ in range(3):
        paths.append(c.start_recording(bpy.context))
        assert wait_for(lambda: c.session.recorder.frames >= 3)
        counts.append(c.session.recorder.frames)
        c.stop_recording(bake=False)
    live.stop_live(bake=False)
    assert len(set(paths)) == 3 and paths[1].endswith("_2.krtake") and paths[2].endswith("_3.krtake")
    assert [krtake.read(p).frame_count for p in paths] == counts  # none overwritten


def test_saving_during_live_keeps_the_users_action(scene_with_rig, tmp_path):
    scene, obj, take, _ = scene_with_rig
    scene.kinect_retarget.loop = True
    user_action = bpy.data.actions.new("UserAction")
    obj.animation_data_create().action = user_action
    assert not user_action.use_fake_user
    live.start_live(bpy.context, use_timer=False)
    assert obj.animation_data.action is None
    blend = str(tmp_path / "during_live.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)  # Ctrl+S while live
    live.stop_live(bake=False)
    assert obj.animation_data.action == user_action and not user_action.use_fake_user  # the user's flag
    bpy.ops.wm.open_mainfile(filepath=blend)
    assert "UserAction" in bpy.data.actions  # the saved file did not drop it


def test_keys_are_anchored_at_the_frame_where_recording_started(scene_with_rig):
    """The first sample arrives half a second after Record: its key lands half a second after that frame."""
    scene, obj, take, _ = scene_with_rig
    scene.frame_current = 40
    gate = threading.Event()

    class Late(_Scripted):
        def _run(self):
            gate.wait(30)
            super()._run()

    c = live.start_live(bpy.context, source=Late(take), use_timer=False)
    c.start_recording(bpy.context)
    rec_path = c.recording["path"]
    wait_for(lambda: False, seconds=0.5)
    gate.set()
    run_live()
    rec = krtake.read(rec_path)
    fps = scene.render.fps / scene.render.fps_base
    assert rec.times[0] >= 0.45
    action = obj.animation_data.action
    curve = action.layers[0].strips[0].channelbag(action.slots[0]).fcurves.find(
        'pose.bones["SpineMid"].rotation_quaternion', index=0)
    keys = np.array([k.co[0] for k in curve.keyframe_points])
    assert keys[0] == 40 + round(rec.times[0] * fps) >= 40 + round(0.45 * fps)
    assert keys[-1] == keys[0] + round((rec.times[-1] - rec.times[0]) * fps)
