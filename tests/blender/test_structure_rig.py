"""A real Blender armature with every bone renamed: Blender's human metarig (face, fingers, palms, breasts,
heels) mapped by structure exactly as its preset maps it, printed by `info --rig`, and baked with `auto`."""
import json
import subprocess
import sys

import numpy as np

from kinect_retarget.core.presets import RIGIFY_METARIG


def _renamed_metarig(bpy):
    import addon_utils
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    obj = bpy.context.object
    rng = np.random.default_rng(16)
    back = {}
    for bone in obj.data.bones:
        new = "".join(rng.choice(list("qwertyuiopasdfghjklzxcvbnm0123456789"), 9))
        back[new] = bone.name
        bone.name = new
    return obj, back


def test_renamed_metarig_maps_by_structure_prints_and_bakes(bpy_empty, tmp_path, data_dir):
    from kinect_retarget.blender.bake_take import bake_take
    from kinect_retarget.core.pipeline import RetargetSettings
    from kinect_retarget.takes import load_take
    bpy = bpy_empty
    obj, back = _renamed_metarig(bpy)
    path = tmp_path / "renamed.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "info", "--rig", str(path), "--json"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    info = json.loads(r.stdout.strip().splitlines()[-1])  # after what Blender prints when it opens the file
    assert info["preset"] == "structure"
    assert {back[b]: j for b, j in info["mapping"].items()} == RIGIFY_METARIG
    assert info["found"]["ElbowLeft"].startswith(next(b for b, o in back.items() if o == "upper_arm.L"))
    text = subprocess.run([sys.executable, "-m", "kinect_retarget", "info", "--rig", str(path)],
                          capture_output=True, text=True, timeout=300).stdout
    assert "structure" in text and "ElbowLeft" in text
    take = load_take(data_dir / "kinect_v2" / "Ges01_wavehand.csv").slice(slice(0, 60))
    res = bake_take(obj, take, preset="auto", settings=RetargetSettings(filter="none", fps=take.rate))
    assert res.preset == "structure"
    assert {back[b] for b in res.motion.bone_names} >= {"upper_arm.L", "forearm.R", "thigh.L", "spine"}


def test_sidebar_fills_the_table_by_structure(registered):
    bpy = registered
    obj, back = _renamed_metarig(bpy)
    s = bpy.context.scene.kinect_retarget
    s.target = obj
    assert bpy.ops.kinect_retarget.mapping_from_preset() == {"FINISHED"}
    assert {back[row.bone]: row.joint for row in s.mapping if row.enabled} == RIGIFY_METARIG
