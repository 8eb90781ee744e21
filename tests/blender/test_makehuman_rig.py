"""A real third-party skeleton: MakeHuman's default skeleton (A-pose, its own bone rolls from its rotation
planes, 163 bones, twist bones in the limbs) built as a Blender armature, then a take baked with the
makehuman preset (found by `auto`). The rig is never edited and every mapped limb follows the performer."""
import json

import numpy as np
import pytest

from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.bake_options import BakeOptions
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.takes import load_take

SOLVER_ONLY = BakeOptions(feet="off")  # the solver's own directions: planted feet would bend the legs


def _obj_vertices(path):
    verts = []
    with open(path) as fh:
        for line in fh:
            if line.startswith("v "):
                verts.append([float(x) for x in line.split()[1:4]])
    return np.array(verts)


def build_makehuman_armature(bpy, data):
    mh = data / "meshes" / "makehuman"
    skel = json.loads((mh / "default.mhskel").read_text())
    verts = _obj_vertices(mh / "base.obj")
    joints = {name: verts[idx].mean(axis=0) for name, idx in skel["joints"].items()}

    def blender(p):  # decimetres, Y-up -> metres, Z-up, facing -Y
        return (0.1 * p[0], -0.1 * p[2], 0.1 * p[1])
    arm = bpy.data.armatures.new("MakeHuman")
    obj = bpy.data.objects.new("MakeHuman", arm)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    bones = skel["bones"]
    for name, b in bones.items():
        eb = arm.edit_bones.new(name)
        eb.head, eb.tail = blender(joints[b["head"]]), blender(joints[b["tail"]])
        plane = skel["planes"].get(b["rotation_plane"])
        if plane:
            a, c, d = (np.array(blender(joints[p])) for p in plane)
            normal = np.cross(c - a, d - c)
            if np.linalg.norm(normal) > 1e-9:
                eb.align_roll(tuple(normal / np.linalg.norm(normal)))
    for name, b in bones.items():
        if b["parent"]:
            arm.edit_bones[name].parent = arm.edit_bones[b["parent"]]
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def test_bake_onto_makehuman_skeleton(bpy_empty, data_dir):
    from kinect_retarget.blender.bake_take import bake_take
    bpy = bpy_empty
    obj = build_makehuman_armature(bpy, data_dir)
    rest_before = np.array([np.array(b.matrix_local) for b in obj.data.bones])
    take = load_take(data_dir / "mocap_bvh" / "131_02.bvh").slice(slice(0, 240, 4))
    res = bake_take(obj, take, preset="auto",
                   settings=RetargetSettings(filter="none", fps=take.rate),  # keys on the take's samples
                   options=SOLVER_ONLY)
    assert res.preset == "makehuman"
    src = kinect_to_blender(take.positions[res.motion.samples])
    sk = take.skeleton
    errs = []
    for i, f in enumerate(res.motion.frames):
        bpy.context.scene.frame_set(int(f))
        for bone, (a, b) in {"upperarm01.L": ("ShoulderLeft", "ElbowLeft"), "lowerarm01.R": ("ElbowRight", "WristRight"),
                             "upperleg01.L": ("HipLeft", "KneeLeft"), "lowerleg01.R": ("KneeRight", "AnkleRight"),
                             "clavicle.L": ("ShoulderCenter", "ShoulderLeft")}.items():
            pb = obj.pose.bones[bone]
            d = np.array(pb.tail - pb.head)
            s = src[i, sk.index(b)] - src[i, sk.index(a)]
            errs.append(np.degrees(np.arccos(np.clip(d @ s / np.linalg.norm(d) / np.linalg.norm(s), -1, 1))))
    assert np.mean(errs) < 0.1 and np.max(errs) < 0.5
    np.testing.assert_array_equal(rest_before, np.array([np.array(b.matrix_local) for b in obj.data.bones]))
    # root motion scaled by n = MakeHuman leg / performer leg
    assert res.motion.root_bone == "root"
    assert np.isfinite(res.motion.root_location).all()


# The same real skeleton under other naming conventions: each preset's table must drive its rig.
RENAMES = {
    "mixamo": {"root": "mixamorig:Hips", "spine04": "mixamorig:Spine", "spine01": "mixamorig:Spine2",
               "neck01": "mixamorig:Neck", "head": "mixamorig:Head",
               **{f"{mh}.{s}": f"mixamorig:{side}{mx}" for s, side in (("L", "Left"), ("R", "Right"))
                  for mh, mx in (("clavicle", "Shoulder"), ("upperarm01", "Arm"), ("lowerarm01", "ForeArm"),
                                 ("wrist", "Hand"), ("upperleg01", "UpLeg"), ("lowerleg01", "Leg"),
                                 ("foot", "Foot"))}},
    "hanim": {"root": "sacroiliac", "spine04": "vl5", "spine01": "vt1", "neck01": "vc4", "head": "skullbase",
              **{f"{mh}.{s}": f"{s.lower()}_{ha}" for s in ("L", "R")
                 for mh, ha in (("clavicle", "sternoclavicular"), ("upperarm01", "shoulder"),
                                ("lowerarm01", "elbow"), ("wrist", "wrist"), ("upperleg01", "hip"),
                                ("lowerleg01", "knee"), ("foot", "ankle"))}},
}


@pytest.mark.parametrize("preset", sorted(RENAMES))
def test_presets_drive_renamed_skeleton(bpy_empty, data_dir, preset):
    from kinect_retarget.blender.bake_take import bake_take
    bpy = bpy_empty
    obj = build_makehuman_armature(bpy, data_dir)
    for old, new in RENAMES[preset].items():
        obj.data.bones[old].name = new
    take = load_take(data_dir / "kinect_v2" / "Ges03_drawlines.csv")
    res = bake_take(obj, take, preset="auto",
                   settings=RetargetSettings(filter="none", fps=take.rate))  # keys on the take's samples
    assert res.preset == preset
    upper = RENAMES[preset]["upperarm01.R"]
    src = kinect_to_blender(take.positions[res.motion.samples])
    sk = take.skeleton
    errs = []
    for i in range(0, len(res.motion.frames), 10):
        bpy.context.scene.frame_set(int(res.motion.frames[i]))
        pb = obj.pose.bones[upper]
        d = np.array(pb.tail - pb.head)
        s = src[i, sk.index("ElbowRight")] - src[i, sk.index("ShoulderRight")]
        errs.append(np.degrees(np.arccos(np.clip(d @ s / np.linalg.norm(d) / np.linalg.norm(s), -1, 1))))
    assert np.max(errs) < 0.5
