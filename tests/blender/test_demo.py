"""Demo pieces with the real bpy wheel: the capsule body bound to a baked rig, and one Workbench still."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
from tools.demo_body import add_body_mesh, body_bones, bone_radius
from kinect_retarget.blender.io.workbench_render import stage_and_render
from kinect_retarget.takes import kinect_v2_csv

WAVE_FRAME = 60  # Ges01: the performer's right hand is up, waving, around here


@pytest.fixture
def baked_rig(data_dir):
    """Generated Kinect rig with the first 70 frames of a real Kinect v2 take baked on it."""
    take = kinect_v2_csv.read(data_dir / "kinect_v2" / "Ges01_wavehand.csv").slice(slice(0, 70))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    obj = new_generated_rig(bpy.context.scene, take)
    bake_take(obj, take, preset="kinect")
    return obj


def _rest_state(obj):
    bones = obj.data.bones
    return [b.name for b in bones], np.array([np.array(b.matrix_local) for b in bones])


def _evaluated_vertices(obj) -> np.ndarray:
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ob_eval = obj.evaluated_get(depsgraph)
    mesh = ob_eval.to_mesh()
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    ob_eval.to_mesh_clear()
    world = np.array(ob_eval.matrix_world)
    return co.reshape(-1, 3) @ world[:3, :3].T + world[:3, 3]


def test_body_mesh_is_bound_rigidly_and_follows_the_pose(baked_rig):
    obj = baked_rig
    names_before, rest_before = _rest_state(obj)
    body = add_body_mesh(obj)

    names_after, rest_after = _rest_state(obj)
    assert names_after == names_before and np.allclose(rest_after, rest_before)  # armature untouched
    assert body.parent == obj
    mods = [m for m in body.modifiers if m.type == "ARMATURE"]
    assert len(mods) == 1 and mods[0].object == obj and mods[0].use_vertex_groups
    groups = [g.name for g in body.vertex_groups]
    assert groups == body_bones(obj) and "HandRight" in groups and "KneeLeft" in groups
    membership = np.array([[(g.group, g.weight) for g in v.groups] for v in body.data.vertices])
    assert membership.shape == (len(body.data.vertices), 1, 2)      # one group per vertex
    assert np.all(membership[:, 0, 1] == 1.0)                       # rigid weights

    # posed: the right hand's capsule sits on the posed HandRight bone, not where it was at rest
    bpy.context.scene.frame_set(WAVE_FRAME)
    verts = _evaluated_vertices(body)
    hand = groups.index("HandRight")
    centre = verts[membership[:, 0, 0] == hand].mean(axis=0)
    pb = obj.pose.bones["HandRight"]
    world = np.array(obj.matrix_world)
    mid = world[:3, :3] @ ((np.array(pb.head) + np.array(pb.tail)) / 2) + world[:3, 3]
    rest_mid = world[:3, :3] @ np.array(obj.data.bones["HandRight"].head_local) + world[:3, 3]
    assert np.linalg.norm(centre - mid) < 0.02
    assert np.linalg.norm(mid - rest_mid) > 0.2  # the hand really moved: the check above means something


def test_one_still_renders_with_the_right_hand_on_the_image_left(baked_rig, tmp_path):
    body = add_body_mesh(baked_rig)
    (path,) = stage_and_render(bpy.context.scene, [body], [WAVE_FRAME], str(tmp_path), "smoke",
                               note="smoke", resolution=(160, 120))
    assert path.endswith("smoke_f0060.png") and (tmp_path / "smoke_f0060.png").stat().st_size > 1000
    image = bpy.data.images.load(path)
    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    rgb = px.reshape(h, w, 4)[..., :3]
    assert (w, h) == (160, 120)
    assert rgb.std(axis=(0, 1)).max() > 0.05                        # not a uniform image
    red = (rgb[..., 0] > rgb[..., 1] + 0.2) & (rgb[..., 0] > rgb[..., 2] + 0.2)   # the character's right
    blue = (rgb[..., 2] > rgb[..., 0] + 0.2)                                      # its left
    assert red.sum() > 50 and blue.sum() > 50
    # facing the camera at -Y, the character's right side is on the left of the picture
    columns = np.arange(w)
    assert (red * columns).sum() / red.sum() < (blue * columns).sum() / blue.sum()
    # and the hand the performer waves (their right) is the raised one: the highest coloured pixel is red
    rows = np.arange(h)[:, None]  # pixel rows come bottom row first from Blender
    assert (rows * red).max() > (rows * blue).max()


def test_body_bones_skip_face_and_fingers_on_the_human_metarig():
    import addon_utils  # importable only once bpy is loaded

    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rigify", default_set=True)  # after read_factory_settings, which disables add-ons
    bpy.ops.object.armature_human_metarig_add()
    metarig = bpy.context.view_layer.objects.active
    names = body_bones(metarig)
    for limb in ("upper_arm.L", "forearm.R", "thigh.L", "shin.R", "spine", "spine.006"):
        assert limb in names
    assert not [n for n in names if n.startswith(("f_", "thumb", "lip", "lid", "brow", "jaw", "ear", "nose"))]
    body = add_body_mesh(metarig)
    assert [g.name for g in body.vertex_groups] == names


def test_add_body_mesh_rejects_what_it_cannot_bind(baked_rig):
    mesh_obj = bpy.data.objects.new("NotARig", bpy.data.meshes.new("NotARig"))
    with pytest.raises(ValueError, match="armature"):
        add_body_mesh(mesh_obj)
    with pytest.raises(ValueError, match="'Tail'"):
        add_body_mesh(baked_rig, bones=["HandRight", "Tail"])
    with pytest.raises(ValueError, match="no deform bone"):
        add_body_mesh(baked_rig, bones=[])


@pytest.mark.parametrize("part, names", [
    ("upper arm", ["ElbowLeft", "DEF-upper_arm.L", "mixamorig:LeftArm", "upperarm01.L", "upper_arm.R"]),
    ("forearm", ["WristRight", "DEF-forearm.R.001", "mixamorig:RightForeArm", "lowerarm02.R", "forearm.L"]),
    ("thigh", ["KneeLeft", "DEF-thigh.L", "mixamorig:LeftUpLeg", "upperleg02.L"]),
    ("shin", ["AnkleRight", "DEF-shin.R", "mixamorig:RightLeg", "lowerleg01.R"]),
    ("torso", ["SpineMid", "Spine", "ShoulderCenter", "HipCenter", "DEF-spine.002", "mixamorig:Hips"]),
    ("head", ["Head", "DEF-spine.006", "mixamorig:Head", "head"]),
])
def test_bone_names_of_every_preset_get_the_same_capsule_per_body_part(part, names):
    radii = {name: bone_radius(name, 0.3, 1.75) for name in names}
    assert len(set(radii.values())) == 1, f"{part}: {radii}"


def test_capsule_sizes_follow_the_body():
    r = {name: bone_radius(name, 0.3, 1.75) for name in ("Head", "Neck", "SpineMid", "ElbowLeft", "WristLeft",
                                                         "KneeLeft", "AnkleLeft", "HandLeft")}
    assert r["SpineMid"] > r["Head"] > r["Neck"]
    assert r["KneeLeft"] > r["AnkleLeft"] and r["ElbowLeft"] > r["WristLeft"] >= r["HandLeft"]


def _demo_module():
    path = Path(__file__).resolve().parents[2] / "tools" / "demo.py"
    spec = importlib.util.spec_from_file_location("kr_demo_tool", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def test_demo_tool_bakes_saves_and_renders_and_names_a_bad_take(data_dir, tmp_path, capsys):
    demo = _demo_module()
    bad = tmp_path / "broken.csv"
    bad.write_text("not,a,take\n")
    take = data_dir / "mocap_bvh" / "131_03.bvh"
    status = demo.main(["--out", str(tmp_path / "out"), "--takes", str(bad), str(take), "--no-rigify",
                        "--stills", "2", "--resolution", "160x120"])
    printed = capsys.readouterr().out
    assert status == 1                                     # one take failed ...
    assert "broken.csv" in printed and "unknown take format" in printed
    assert "1 of 2 bakes done" in printed                  # ... and the other still baked
    out = tmp_path / "out"
    assert (out / "131_03__kinect.blend").stat().st_size > 0
    stills = sorted((out / "renders").glob("131_03__kinect_f*.png"))
    assert len(stills) == 2 and (out / "renders" / "131_03__kinect_sheet.png").is_file()
    bpy.ops.wm.open_mainfile(filepath=str(out / "131_03__kinect.blend"))
    rig = bpy.data.objects["KinectRig"]
    assert rig.animation_data.action is not None and rig.animation_data.action_slot is not None
    assert bpy.context.scene.camera is not None
    assert [o for o in bpy.data.objects if o.get("kinect_retarget_body") == "KinectRig"]
