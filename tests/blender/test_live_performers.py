"""Several performers live: an OSC stream with two numbered users (NI mate's `[U]`) drives two rigs through
the live pump, each rig its own user; a two-person take played from the sidebar drives the target and an
other performer's rig, each recording its own body; Bake Take bakes each body onto its rig."""
from __future__ import annotations

import socket
import threading
import time

import bpy
import numpy as np
import pytest

import kinect_retarget
from kinect_retarget.blender.io.kinect_rig import build_kinect_rig
from kinect_retarget.blender.live import live_runtime as live
from kinect_retarget.blender.live.live_controller import LiveSettings
from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.kinect_rig_layout import median_segment_lengths
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.core.skeletons import KINECT_V2
from kinect_retarget.sources import OscReceiver
from kinect_retarget.sources.osc_codec import encode_message
from kinect_retarget.takes import krtake, load_take
from tests.takes.two_performers import performers, write_two_person_ntu


@pytest.fixture
def two_rigs(data_dir):
    kinect_retarget.register()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    first, second = performers(data_dir)
    second.positions[..., 0] += 1.0  # as the two-person take has it
    scene = bpy.context.scene
    rigs = [build_kinect_rig(scene, KINECT_V2, median_segment_lengths(t), name)
            for t, name in ((first, "Alice"), (second, "Bob"))]
    bpy.context.view_layer.objects.active = rigs[0]
    yield scene, rigs, (first, second)
    live.stop_live(bake=False)
    kinect_retarget.unregister()
    bpy.ops.wm.read_factory_settings(use_empty=True)


def _limb_error(obj, positions) -> float:
    """Mean angle (degrees) between the rig's bones and the frame's limbs (bone J: parent joint -> J)."""
    bpy.context.view_layer.update()
    sk, p = KINECT_V2, kinect_to_blender(positions)
    errs = []
    for j, name in enumerate(sk.joints):
        if sk.parents[j] < 0:
            continue
        pb = obj.pose.bones[name]
        d = np.array(obj.matrix_world @ pb.tail) - np.array(obj.matrix_world @ pb.head)
        src = p[j] - p[sk.parents[j]]
        if np.linalg.norm(src) > 1e-6:
            errs.append(np.degrees(np.arccos(np.clip(d @ src / np.linalg.norm(d) / np.linalg.norm(src), -1, 1))))
    return float(np.mean(errs))


def _wait(cond, seconds=60.0) -> bool:
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        live.pump_live()
        if cond():
            return True
        time.sleep(0.003)
    return cond()


def test_osc_with_two_users_drives_two_rigs(two_rigs, tmp_path):
    scene, (alice, bob), (first, second) = two_rigs
    src = OscReceiver(port=0)
    settings = LiveSettings(retarget=RetargetSettings(filter="none"), bake_on_stop=True)
    c = live.start_live(bpy.context, src, settings, armature=alice, body=0, followers=[(bob, 1)], use_timer=False)
    assert [f.obj_name for f in c.followers] == ["Bob"] and live.status()["performers"] == [("Alice", 0), ("Bob", 1)]
    for ctrl in (c, *c.followers):
        ctrl.session.stale_after = 60.0  # a loaded machine must not skip the frames this test looks at
    c.start_recording(bpy.context, str(tmp_path / "duo.krtake"), play=False)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for i in range(0, 30, 6):
            for user, take in ((1, first), (2, second)):  # NI mate's /Joint_[U], users from 1
                for j, name in enumerate(KINECT_V2.joints):
                    s.sendto(encode_message(f"/{name}_{user}", *map(float, take.positions[i, j])),
                             ("127.0.0.1", src.port))
            s.sendto(encode_message("/NI_mate_sync", "x"), ("127.0.0.1", src.port))
            n = i // 6 + 1
            assert _wait(lambda n=n: c.session.stats.applied == n and c.followers[0].session.stats.applied == n)
            # each rig follows its own user, not the other one
            assert _limb_error(alice, first.positions[i]) < 1.0 and _limb_error(bob, second.positions[i]) < 1.0
            assert _limb_error(alice, second.positions[i]) > 5.0
    live.stop_live()
    # each performer recorded to its own file and baked onto its own rig
    a, b = krtake.read(tmp_path / "duo.krtake"), krtake.read(tmp_path / "duo_body1.krtake")
    assert a.frame_count == b.frame_count == 5
    np.testing.assert_allclose(a.positions[-1], first.positions[24], atol=2e-5)
    np.testing.assert_allclose(b.positions[-1], second.positions[24], atol=2e-5)
    assert alice.animation_data.action is not None and bob.animation_data.action is not None
    assert alice.animation_data.action != bob.animation_data.action
    assert not [t for t in threading.enumerate() if t.name.startswith("kinect_retarget") and t.is_alive()]


def test_a_two_person_take_from_the_sidebar_drives_each_rig_with_its_body(two_rigs, data_dir, tmp_path):
    scene, (alice, bob), (first, second) = two_rigs
    path = write_two_person_ntu(data_dir, tmp_path / "S001C001P001R001A050.skeleton")
    s = scene.kinect_retarget
    s.initialised = True
    s.source, s.take_path, s.speed, s.loop, s.armature, s.body = "TAKE", str(path), 4.0, False, alice, 0
    s.record_dir, s.play_on_record, s.bake_on_stop = str(tmp_path / "rec"), False, False
    bpy.ops.kinect_retarget.performer_add()
    s.performers[0].armature = bob
    assert s.performers[0].body == 1
    c = live.start_live(bpy.context, use_timer=False)
    rec = c.start_recording(bpy.context, play=False)
    assert _wait(lambda: (live.status().get("progress") or (0, 0))[0] > 1)  # the take's frame, behind the fanout
    _wait(lambda: not live.pump_live() and live.controller() is None)
    assert live.controller() is None and live.status()["error"] is None
    a, b = krtake.read(rec), krtake.read(rec.replace(".krtake", "_body1.krtake"))
    ta, tb = load_take(path), load_take(path, body=1)
    for got, want, other in ((a, ta, tb), (b, tb, ta)):  # the take played to its end: its last frame is last
        assert got.frame_count > 30
        np.testing.assert_allclose(got.positions[-1], want.positions[-1], atol=2e-5)
        assert np.abs(got.positions[-1] - other.positions[-1]).max() > 0.5


def test_bake_take_bakes_each_body_onto_its_rig(two_rigs, data_dir, tmp_path):
    scene, (alice, bob), _ = two_rigs
    path = write_two_person_ntu(data_dir, tmp_path / "S001C001P001R001A050.skeleton")
    s = scene.kinect_retarget
    s.initialised = True
    s.armature = alice
    item = s.performers.add()
    item.armature, item.body = bob, 1
    assert bpy.ops.kinect_retarget.bake_take(filepath=str(path), filter="none", fps=30.0, body=0) == {"FINISHED"}
    assert alice.animation_data.action.name != bob.animation_data.action.name
    assert bob.animation_data.action.name.endswith("_body1") or "body1" in bob.animation_data.action.name
    scene.frame_set(31)
    bpy.context.view_layer.update()
    a_hand = np.array(alice.matrix_world @ alice.pose.bones["HandRight"].tail)
    b_hand = np.array(bob.matrix_world @ bob.pose.bones["HandRight"].tail)
    assert np.linalg.norm(a_hand - b_hand) > 0.3  # two different gestures, a metre apart


def test_performer_rows_are_added_and_removed(two_rigs):
    scene, (alice, bob), _ = two_rigs
    s = scene.kinect_retarget
    s.body = 2
    bpy.ops.kinect_retarget.performer_add()
    bpy.ops.kinect_retarget.performer_add()
    assert [p.body for p in s.performers] == [3, 4]  # the next bodies nobody follows yet
    assert bpy.ops.kinect_retarget.performer_remove(index=0) == {"FINISHED"}
    assert [p.body for p in s.performers] == [4]
    with pytest.raises(RuntimeError, match="no performer 5"):
        bpy.ops.kinect_retarget.performer_remove(index=5)
    s.performers[0].armature, s.performers[0].body = bob, 2
    with pytest.raises(ValueError, match="its own body"):  # two rigs on one body: refused, nothing started
        live.start_live(bpy.context, use_timer=False)
    assert live.controller() is None
