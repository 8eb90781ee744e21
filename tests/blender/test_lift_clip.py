"""The clip-tracks path through bpy: a Movie Clip created in the test, tracks named after joints, markers
from real mocap projected through the clip's camera, lifted and baked onto a generated rig."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.lift.video_camera import Camera, view_points
from kinect_retarget.lift.image_sequence import write_png
from kinect_retarget.takes import bvh

W, H, FOCAL = 640, 360, 520.0
# A mix of the naming schemes the docs promise (docs/lifting.md)
TRACK_NAMES = {"HipLeft": "l_hip", "HipRight": "RHip", "KneeLeft": "left knee", "KneeRight": "knee.R",
               "AnkleLeft": "LAnkle", "AnkleRight": "AnkleRight", "ShoulderLeft": "l_shoulder",
               "ShoulderRight": "right_shoulder", "ElbowLeft": "L.Elbow", "ElbowRight": "r_elbow",
               "WristLeft": "l_wrist", "WristRight": "WristRight", "Head": "skullbase", "ShoulderCenter": "neck",
               "FootLeft": "l_toe", "FootRight": "RBigToe"}


@pytest.fixture(scope="module")
def walk_2d(data_dir):
    take = bvh.read(data_dir / "mocap_bvh" / "131_02.bvh")
    pos = take.positions[::4][135:195]  # two seconds of walking at 30 fps
    pos = view_points(pos, 30.0, 5.0, 4.0, pos[:, 0].mean(axis=0))
    return pos, Camera.for_image(W, H, FOCAL).project(pos)


def _clip(bpy, tmp_path, uv, names=TRACK_NAMES, first=1):
    write_png(str(tmp_path / "plate.png"), np.full((H, W, 3), 120 / 255))
    clip = bpy.data.movieclips.load(str(tmp_path / "plate.png"))
    cam = clip.tracking.camera
    cam.sensor_width = 36.0
    cam.focal_length = FOCAL * 36.0 / W
    for joint, name in names.items():
        j = KINECT_V1.index(joint)
        track = clip.tracking.tracks.new(name=name, frame=first)
        for f in range(len(uv)):
            co = (uv[f, j, 0] / W, 1.0 - uv[f, j, 1] / H)
            if f == 0:
                track.markers[0].co = co
            else:
                track.markers.insert_frame(f + first, co=co)
    bpy.context.scene.active_clip = clip
    bpy.context.scene.render.fps = 30
    return clip


def test_clip_markers_read_back_as_pixels(bpy_empty, tmp_path, walk_2d):
    from kinect_retarget.blender.clip_lift import clip_focal_px, tracks_from_clip
    pos, uv = walk_2d
    clip = _clip(bpy_empty, tmp_path, uv)
    assert clip_focal_px(clip) == pytest.approx(FOCAL, rel=1e-4)
    tracks = tracks_from_clip(clip, bpy_empty.context.scene)
    assert tracks.frame_count == len(uv) and tracks.image_size == (W, H)
    for joint in ("KneeLeft", "ElbowLeft", "Head"):
        assert np.allclose(tracks.uv[:, KINECT_V1.index(joint)], uv[:, KINECT_V1.index(joint)], atol=0.02)
    assert tracks.inferred[:, KINECT_V1.index("HipCenter")].all()  # from the two hip tracks


def test_lift_clip_operator_bakes_a_rig(registered, tmp_path, walk_2d):
    bpy = registered
    pos, uv = walk_2d
    _clip(bpy, tmp_path, uv)
    take_path = tmp_path / "lifted.krtake"
    assert bpy.ops.kinect_retarget.lift_clip(armature="__new__", take_path=str(take_path)) == {"FINISHED"}
    rigs = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    assert len(rigs) == 1
    rig = rigs[0]
    action = rig.animation_data.action
    assert action is not None
    assert tuple(action.frame_range) == pytest.approx((1, len(uv)), abs=1)  # keys on the clip's frames
    from kinect_retarget.takes import load_take
    take = load_take(take_path)
    # the baked rig's shin points where the lifted (and the real) shin points
    scene = bpy.context.scene
    for frame in (10, 40):
        scene.frame_set(frame)
        bone = rig.pose.bones["AnkleLeft"]
        shin = np.array(rig.matrix_world @ bone.tail) - np.array(rig.matrix_world @ bone.head)
        k, a = KINECT_V1.index("KneeLeft"), KINECT_V1.index("AnkleLeft")
        lifted = kinect_to_blender(take.positions[frame - 1, a] - take.positions[frame - 1, k])
        real = kinect_to_blender(pos[frame - 1, a] - pos[frame - 1, k])
        cos_lift = shin @ lifted / np.linalg.norm(shin) / np.linalg.norm(lifted)
        cos_real = shin @ real / np.linalg.norm(shin) / np.linalg.norm(real)
        assert cos_lift > np.cos(np.radians(10)) and cos_real > np.cos(np.radians(25))


def test_keys_line_up_with_the_tracked_clip_frames(registered, tmp_path, walk_2d):
    bpy = registered
    pos, uv = walk_2d
    _clip(bpy, tmp_path, uv[:20], first=31)
    assert bpy.ops.kinect_retarget.lift_clip(armature="__new__") == {"FINISHED"}
    rig = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    assert tuple(rig.animation_data.action.frame_range) == pytest.approx((31, 50), abs=0.5)


def test_unknown_track_names_are_a_clear_error(registered, tmp_path, walk_2d):
    bpy = registered
    pos, uv = walk_2d
    _clip(bpy, tmp_path, uv[:5], names={"KneeLeft": "Track", "AnkleLeft": "Track.001"})
    with pytest.raises(RuntimeError, match="no track is named after a joint"):
        bpy.ops.kinect_retarget.lift_clip(armature="__new__")
    assert not [o for o in bpy.data.objects if o.type == "ARMATURE"]


def test_cli_lifts_a_blend_with_a_clip(bpy_empty, tmp_path, walk_2d):
    from kinect_retarget.cli import main
    from kinect_retarget.takes import load_take
    pos, uv = walk_2d
    _clip(bpy_empty, tmp_path, uv)
    blend = tmp_path / "tracked.blend"
    bpy_empty.ops.wm.save_as_mainfile(filepath=str(blend))
    out = tmp_path / "walk.krtake"
    assert main(["lift", str(blend), "--format", "clip", "--out", str(out)]) == 0
    take = load_take(out)
    assert take.frame_count == len(uv)
    assert take.metadata.get("focal_known") is True


# H-Anim humanoid bones (named after the H-Anim joint at their head) as the 'hanim' preset expects them:
# bone -> (head joint, tail joint, parent bone); "Head+" is 10 cm above the head joint. As in the H-Anim
# standard's hierarchy (ISO/IEC 19774, LOA 2+), the sternoclavicular joints hang from vt1, not vl5.
HANIM_BONES = {
    "sacroiliac": ("HipCenter", "Spine", None), "vl5": ("Spine", "ShoulderCenter", "sacroiliac"),
    "vt1": ("ShoulderCenter", "Neck", "vl5"), "skullbase": ("Neck", "Head+", "vt1"),
    **{f"{s}_{bone}": (f"{a}{side}", f"{b}{side}", par.format(s=s)) for s, side in (("l", "Left"), ("r", "Right"))
       for bone, a, b, par in (("sternoclavicular", "Shoulder", "Shoulder", "vt1"),
                               ("shoulder", "Shoulder", "Elbow", "{s}_sternoclavicular"),
                               ("elbow", "Elbow", "Wrist", "{s}_shoulder"), ("wrist", "Wrist", "Hand", "{s}_elbow"),
                               ("hip", "Hip", "Knee", "sacroiliac"), ("knee", "Knee", "Ankle", "{s}_hip"),
                               ("ankle", "Ankle", "Foot", "{s}_knee"))},
}


def _hanim_rig(bpy, rest_kinect: np.ndarray):
    """An H-Anim armature in the CMU T-pose (01_01 frame 0), Blender axes."""
    p = {n: kinect_to_blender(rest_kinect[KINECT_V1.index(n)] - rest_kinect[0]) for n in KINECT_V1.joints}
    p["Neck"] = 0.5 * (p["ShoulderCenter"] + p["Head"])
    p["Head+"] = p["Head"] + np.array([0.0, 0.0, 0.1])
    arm = bpy.data.armatures.new("HAnim")
    obj = bpy.data.objects.new("HAnim", arm)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    for name, (head, tail, _) in HANIM_BONES.items():
        b = arm.edit_bones.new(name)
        # the sternoclavicular bone runs from the neck base to the shoulder
        b.head = p["ShoulderCenter"] if name.endswith("sternoclavicular") else p[head]
        b.tail = p[tail]
    for name, (_, _, parent) in HANIM_BONES.items():
        if parent:
            arm.edit_bones[name].parent = arm.edit_bones[parent]
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def test_lift_bakes_onto_an_hanim_humanoid(bpy_empty, tmp_path, walk_2d, data_dir):
    from kinect_retarget.blender.clip_lift import lift_clip_and_bake
    bpy = bpy_empty
    pos, uv = walk_2d
    clip = _clip(bpy, tmp_path, uv)
    rest = bvh.read(data_dir / "mocap_bvh" / "01_01.bvh").positions[0]
    rig = _hanim_rig(bpy, rest)
    out = lift_clip_and_bake(bpy.context, clip, rig.name, preset="auto")
    assert out.preset == "hanim"
    scene = bpy.context.scene
    for frame in (10, 40):
        scene.frame_set(frame)
        for bone, (a, b) in (("l_knee", ("KneeLeft", "AnkleLeft")), ("r_shoulder", ("ShoulderRight", "ElbowRight"))):
            pb = rig.pose.bones[bone]
            got = np.array(rig.matrix_world @ pb.tail) - np.array(rig.matrix_world @ pb.head)
            real = kinect_to_blender(pos[frame - 1, KINECT_V1.index(b)] - pos[frame - 1, KINECT_V1.index(a)])
            assert got @ real / np.linalg.norm(got) / np.linalg.norm(real) > np.cos(np.radians(30)), bone


def test_hanim_humanoid_renamed_maps_by_structure_as_its_preset(bpy_empty, data_dir):
    """The same armature with every bone renamed at random: structure finds the 'hanim' preset's mapping."""
    from kinect_retarget.core.armature_mapping import structure_mapping_for
    from kinect_retarget.core.presets import PRESETS
    from tests.rigs.humanoid_rigs import Rig, renamed
    rig = _hanim_rig(bpy_empty, bvh.read(data_dir / "mocap_bvh" / "01_01.bvh").positions[0])
    bones = list(rig.data.bones)
    names = [b.name for b in bones]
    plain = Rig(names, np.array([names.index(b.parent.name) if b.parent else -1 for b in bones]),
                np.array([b.head_local for b in bones]), np.array([b.tail_local for b in bones]))
    anon, back = renamed(plain, 7)
    found = structure_mapping_for(anon.names, anon.parents, anon.heads, anon.tails).mapping
    assert {back[b]: j for b, j in found.items()} == {b: j for b, j in PRESETS["hanim"].items() if b in names}


def test_joint_tracker_writes_clip_markers(registered, tmp_path, data_dir):
    """Paper 004's tracker inside Blender: markers on frame 1 of an image-sequence clip of a rendered
    coloured body (real motion), followed through the clip."""
    from kinect_retarget.sim.body_imagery import background, render
    bpy = registered
    take = bvh.read(data_dir / "mocap_bvh" / "131_02.bvh")
    pos = view_points(take.positions[::4][150:165], 80.0, 5.0, 3.5, take.positions[600, 0])
    size, cam = (320, 240), Camera.for_image(320, 240, 300.0)
    rng = np.random.default_rng(4)
    bg = background(*size, rng)
    (tmp_path / "seq").mkdir()
    for i, p in enumerate(pos):
        write_png(str(tmp_path / "seq" / f"body_{i + 1:04d}.png"), render(p, cam, *size, bg, rng))
    uv = cam.project(pos)
    clip = bpy.data.movieclips.load(str(tmp_path / "seq" / "body_0001.png"))
    names = {"ElbowLeft": "l_elbow", "KneeRight": "r_knee", "Head": "skullbase", "HipCenter": "pelvis"}
    for joint, name in names.items():
        t = clip.tracking.tracks.new(name=name, frame=1)
        j = KINECT_V1.index(joint)
        t.markers[0].co = (uv[0, j, 0] / size[0], 1 - uv[0, j, 1] / size[1])
    bpy.context.scene.active_clip = clip
    bpy.context.scene.frame_current = 1
    assert bpy.ops.kinect_retarget.track_clip_joints() == {"FINISHED"}
    errs = []
    for joint, name in names.items():
        track = clip.tracking.tracks[name]
        j = KINECT_V1.index(joint)
        for f in range(2, len(pos) + 1):
            m = track.markers.find_frame(f, exact=True)
            assert m is not None
            got = (m.co[0] * size[0], (1 - m.co[1]) * size[1])
            errs.append(np.hypot(got[0] - uv[f - 1, j, 0], got[1] - uv[f - 1, j, 1]))
    assert np.mean(errs) < 6.0
    idx = [KINECT_V1.index(j) for j in names]
    moved = np.linalg.norm(uv[1:, idx] - uv[:1, idx], axis=-1).mean()
    assert moved > 2 * np.mean(errs), (moved, np.mean(errs))  # the joints really moved


def test_paper_method_gives_the_keyed_hanim_figure(registered, tmp_path, walk_2d):
    """Lift Clip with Method = Paper onto 'New H-Anim Figure': 16 H-Anim bones keyed with Euler angles
    ('XYZ', β = 0); evaluated, every bone points along the lifted take's bone."""
    bpy = registered
    from kinect_retarget.blender.clip_lift import NEW_HANIM, lift_clip_and_bake
    from kinect_retarget.lift import hanim
    pos, uv = walk_2d
    clip = _clip(bpy, tmp_path, uv)
    take_path = tmp_path / "paper.krtake"
    obj = lift_clip_and_bake(bpy.context, clip, NEW_HANIM, method="paper", take_path=str(take_path))
    assert [b.name for b in obj.data.bones] == list(hanim.NAMES)
    assert all(pb.rotation_mode == "XYZ" for pb in obj.pose.bones)
    curves = obj.animation_data.action.layers[0].strips[0].channelbags[0].fcurves
    beta = [fc for fc in curves if fc.data_path.endswith("rotation_euler") and fc.array_index == 1]
    assert len(beta) == 16 and all(abs(k.co[1]) < 1e-9 for fc in beta for k in fc.keyframe_points)
    from kinect_retarget.takes import load_take
    take = load_take(take_path)
    assert take.metadata["method"] == "paper"
    lifted = kinect_to_blender(take.positions)
    for f in (0, len(uv) // 2):
        bpy.context.scene.frame_set(1 + f)
        for k, name in enumerate(hanim.NAMES):
            if hanim.TO[k] < 0:
                continue
            pb = obj.pose.bones[name]
            got = np.array(pb.tail) - np.array(pb.head)
            want = lifted[f, hanim.TO[k]] - lifted[f, hanim.AT[k]]
            cos = got @ want / np.linalg.norm(got) / np.linalg.norm(want)
            assert cos > 0.9999, (f, name, cos)


def test_cli_lift_paper_writes_the_hanim_blend(bpy_empty, tmp_path, walk_2d):
    from kinect_retarget.cli import main
    pos, uv = walk_2d
    _clip(bpy_empty, tmp_path, uv)
    blend = tmp_path / "tracked.blend"
    bpy_empty.ops.wm.save_as_mainfile(filepath=str(blend))
    out, fig = tmp_path / "walk.krtake", tmp_path / "hanim.blend"
    assert main(["lift", str(blend), "--format", "clip", "--out", str(out), "--method", "paper",
                 "--hanim", str(fig)]) == 0
    assert fig.is_file()
    assert main(["lift", str(blend), "--format", "clip", "--out", str(out), "--method", "paper",
                 "--focal", "500"]) == 2  # the paper's camera has no focal length: refused, not ignored
