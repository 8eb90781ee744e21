"""Kinect v2 hands on a rig with finger bones (Blender's Rigify human metarig): the hand rolls to the
performer's thumb, the hand states curl the fingers smoothly, and Kinect v1 takes leave the fingers alone."""
import numpy as np
import pytest

from kinect_retarget.core.bake_options import BakeOptions
from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.hand_pose import CLOSED, OPEN
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.core.quat import angle_between
from kinect_retarget.takes import load_take


@pytest.fixture
def metarig(bpy_empty):
    import addon_utils
    addon_utils.enable("rigify", default_set=True)
    bpy_empty.ops.object.armature_human_metarig_add()
    return bpy_empty.context.object


def _bake(obj, take, hands="auto"):
    from kinect_retarget.blender.bake_take import bake_take
    messages = []
    res = bake_take(obj, take, preset="auto", settings=RetargetSettings(filter="none", fps=take.rate),
                    options=BakeOptions(hands=hands), report=lambda level, msg: messages.append(msg))
    return res, messages[-1]


def _toward_palm(obj, hand, side, finger_base):
    """Degrees a finger's first segment is turned from the hand's length toward the palm's side (the side
    the thumb sits on), about the hand's curl axis."""
    from kinect_retarget.blender.io.finger_rig import hand_rig
    rig = hand_rig(obj, hand, side)
    m = np.array(obj.pose.bones[hand].matrix)[:3, :3]
    m /= np.linalg.norm(m, axis=0)
    palm = m @ np.cross(rig.curl_local, [0.0, 1.0, 0.0])  # curl = Y x palm
    pb = obj.pose.bones[finger_base]
    d = np.array(pb.tail) - np.array(pb.head)
    return float(np.degrees(np.arctan2(palm @ d, m[:, 1] @ d)))


def _thumb_side_errors(bpy, obj, res, take):
    """Degrees between the hand's thumb side (its rest thumb side carried by the posed hand) and the
    performer's hand -> thumb, both seen across the hand's own axis."""
    from kinect_retarget.blender.io.finger_rig import hand_rig
    p = kinect_to_blender(res.motion.extras["positions"])
    sk = take.skeleton
    rigs = {side: hand_rig(obj, f"hand.{side[0]}", side) for side in ("Left", "Right")}
    errs = []
    for i in range(0, len(res.motion.frames), 3):
        bpy.context.scene.frame_set(int(res.motion.frames[i]))
        for side, rig in rigs.items():
            m = np.array(obj.pose.bones[rig.hand].matrix)[:3, :3]
            m /= np.linalg.norm(m, axis=0)
            y = m[:, 1]
            a, b = m @ rig.thumb_local, p[i, sk.index(f"Thumb{side}")] - p[i, sk.index(f"Hand{side}")]
            a, b = a - (a @ y) * y, b - (b @ y) * y
            errs.append(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))))
    return np.array(errs)


def test_v2_hands_roll_to_the_thumb_and_curl_from_hand_states(metarig, data_dir):
    bpy = __import__("bpy")
    take = load_take(data_dir / "kinect_v2" / "recorded_skeleton.json")
    assert take.hand_states is not None
    rest_tilt = _toward_palm(metarig, "hand.L", "Left", "f_middle.01.L")
    res, msg = _bake(metarig, take)
    assert "hands: 30 finger bones keyed" in msg and "hand states" in msg
    on = _thumb_side_errors(bpy, metarig, res, take)
    m = res.motion
    # curls: the middle finger's reach (base to tip) is short in a fist, long with the hand open
    reach = {OPEN: [], CLOSED: []}
    for i in range(len(m.frames)):
        state = int(take.hand_states[m.samples[i], 0])
        if state in reach and i > 10 and int(take.hand_states[m.samples[i - 10], 0]) == state:  # settled
            bpy.context.scene.frame_set(int(m.frames[i]))
            pb = metarig.pose.bones
            reach[state].append(np.linalg.norm(np.array(pb["f_middle.03.L"].tail) - np.array(pb["f_middle.01.L"].head)))
            if state == CLOSED:  # curled toward the palm, not backwards
                assert _toward_palm(metarig, "hand.L", "Left", "f_middle.01.L") > rest_tilt + 30
    assert reach[OPEN] and reach[CLOSED] and np.mean(reach[CLOSED]) < 0.7 * np.mean(reach[OPEN])
    # smooth: no finger joint turns by more than 25 degrees from one key to the next
    k = m.bone_names.index("f_middle.02.L")
    assert np.degrees(angle_between(m.quats[1:, k], m.quats[:-1, k])).max() < 25.0
    off, msg_off = _bake(metarig, take, hands="off")
    assert "hands:" not in msg_off and "f_middle.02.L" not in off.motion.bone_names
    without = _thumb_side_errors(bpy, metarig, off, take)
    print(f"thumb side error: hands on median {np.median(on):.2f}° p90 {np.percentile(on, 90):.1f}°, "
          f"off median {np.median(without):.1f}° p90 {np.percentile(without, 90):.1f}°")
    assert np.median(on) < 1.0 and np.median(without) > 10.0


def test_v1_takes_leave_the_fingers_alone(metarig):
    take = load_take("sample_takes/kinect_v1_cmu_131_03_hop.krtake").slice(slice(0, 30))
    res, msg = _bake(metarig, take)
    assert "hands:" not in msg and not any(b.startswith(("f_", "thumb")) for b in res.motion.bone_names)


HAND_BONES = ("hand.L", "f_index.01.L", "f_middle.01.L", "thumb.01.R", "hand.R")


def test_live_hands_equal_the_bake_of_the_recording(metarig, tmp_path):
    """A live v2 source rolls the hands and bends the fingers as the bake of its recording keys them."""
    import time
    import bpy
    import kinect_retarget
    from kinect_retarget.blender.live import live_runtime as live
    from kinect_retarget.takes import krtake

    from .test_live import LockstepPlayback  # every frame shown, however loaded the machine is
    take = load_take("sample_takes/kinect_v2_ges03_drawlines.krtake").slice(slice(0, 45))
    kinect_retarget.register()
    try:
        scene = bpy.context.scene
        scene.render.fps = 30
        s = scene.kinect_retarget
        s.initialised, s.armature, s.record_dir, s.play_on_record, s.filter = True, metarig, str(tmp_path), False, \
            "none"
        rest = np.array([metarig.pose.bones[b].rotation_quaternion[:] for b in HAND_BONES])
        seen = []
        c = live.start_live(bpy.context, source=LockstepPlayback(take, speed=2.0), use_timer=False)
        assert len(c.hands) == 2
        apply = c.session.apply
        c.session.apply = lambda pose: (apply(pose), seen.append(
            (pose.time, np.array([metarig.pose.bones[b].rotation_quaternion[:] for b in HAND_BONES]))))
        c.start_recording(bpy.context)
        rec_path, start = c.recording["path"], c.recording["frame_start"]
        end = time.perf_counter() + 60
        while live.pump_live() and time.perf_counter() < end:
            time.sleep(0.003)
        assert live.controller() is None and len(seen) >= 5
        assert np.degrees(angle_between(seen[-1][1], rest)).max() > 1.0  # live moved the hands and fingers
        rec = krtake.read(rec_path)
        first = start + round(rec.times[0] * 30)  # the bake anchors its keys where recording started

        def frame(i):
            return first + round((rec.times[i] - rec.times[0]) * 30)
        checked = 0
        for t, held in seen:
            i = int(np.argmin(np.abs(rec.times - t)))
            if i and frame(i) == frame(i - 1):
                continue  # another sample owns this frame's key
            scene.frame_set(frame(i))
            baked = np.array([metarig.pose.bones[b].rotation_quaternion[:] for b in HAND_BONES])
            assert np.degrees(angle_between(baked, held)).max() < 1e-3
            checked += 1
        assert checked >= 5
    finally:
        live.stop_live(bake=False)
        kinect_retarget.unregister()


def test_mixamo_named_fingers_on_a_real_skeleton(bpy_empty, data_dir):
    """MakeHuman's skeleton (its own A-pose hands and bone rolls) under Mixamo's names, fingers included."""
    from .test_makehuman_rig import RENAMES, build_makehuman_armature
    bpy = bpy_empty
    obj = build_makehuman_armature(bpy, data_dir)
    names = dict(RENAMES["mixamo"])
    for s, side in (("L", "Left"), ("R", "Right")):
        for n, finger in enumerate(("Thumb", "Index", "Middle", "Ring", "Pinky"), start=1):
            names.update({f"finger{n}-{i}.{s}": f"mixamorig:{side}Hand{finger}{i}" for i in (1, 2, 3)})
    for old, new in names.items():
        obj.data.bones[old].name = new
    take = load_take(data_dir / "kinect_v2" / "recorded_skeleton.json")
    rest_tilt = _toward_palm(obj, "mixamorig:LeftHand", "Left", "mixamorig:LeftHandMiddle1")
    res, msg = _bake(obj, take)
    assert res.preset == "mixamo" and "hands: 30 finger bones keyed" in msg
    m, pb = res.motion, obj.pose.bones
    reach = {OPEN: [], CLOSED: []}
    for i in range(10, len(m.frames)):
        state = int(take.hand_states[m.samples[i], 0])
        if state in reach and int(take.hand_states[m.samples[i - 10], 0]) == state:
            bpy.context.scene.frame_set(int(m.frames[i]))
            tip = np.array(pb["mixamorig:LeftHandMiddle3"].tail) - np.array(pb["mixamorig:LeftHandMiddle1"].head)
            reach[state].append(np.linalg.norm(tip))
            if state == CLOSED:  # curled toward the palm, not backwards
                assert _toward_palm(obj, "mixamorig:LeftHand", "Left", "mixamorig:LeftHandMiddle1") > rest_tilt + 30
    assert np.mean(reach[CLOSED]) < 0.8 * np.mean(reach[OPEN])
