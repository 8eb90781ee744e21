"""The generated Rigify control rig (706 bones: FK and IK controls, ORG/DEF/MCH chains, tweak bones) with every
bone renamed to a random string in Blender (constraints and drivers follow the new names) maps by structure
exactly as the 'rigify' preset maps the original (core/control_rig_mapping.py), also generated from a T-posed
metarig and from the Basic Human metarig; `info --rig` prints it, the sidebar fills its table with it, and a
take baked onto the renamed rig equals the bake onto the original."""
import json
import subprocess
import sys

import numpy as np
import pytest

from kinect_retarget.core.presets import PRESETS, RIGIFY_FK_SWITCHES, build_mapping, detect_preset
from tests.rigs.control_rigs import rename_bones

SAMPLES = __import__("pathlib").Path(__file__).resolve().parents[2] / "sample_takes"


def _open(bpy, path, seed: int | None = None):
    """The generated rig from `path`; with a seed every bone renamed. Returns (rig, {new name: old name})."""
    bpy.ops.wm.open_mainfile(filepath=str(path))
    obj = next(o for o in bpy.data.objects if o.type == "ARMATURE" and "upper_arm_fk.L" in o.data.bones)
    return obj, (rename_bones(obj, seed) if seed is not None else {b.name: b.name for b in obj.data.bones})


@pytest.mark.parametrize("seed", [5, 16])
def test_rigify_control_rig_renamed_maps_exactly_as_its_preset(bpy_empty, rigify_rig_path, tmp_path, seed):
    from kinect_retarget.blender.io.rig_reader import fk_switch_bones, target_rig_from_object
    bpy = bpy_empty
    obj, back = _open(bpy, rigify_rig_path, seed)
    assert len(back) == 706 and not set(back) & set(back.values())
    rig = target_rig_from_object(obj)
    with pytest.raises(ValueError):
        detect_preset(rig.bone_names)   # no preset knows these names
    used, mapping = build_mapping("auto", rig.bone_names, None, rig)
    assert used == "structure"
    assert {back[b]: j for b, j in mapping.items()} == PRESETS["rigify"]
    # the bake switches the same limbs to FK, found from the rig's drivers
    assert sorted(back[b] for b in fk_switch_bones(obj)) == sorted(RIGIFY_FK_SWITCHES)
    if seed == 16:  # `info --rig` prints it (a second Blender process: once)
        path = tmp_path / "renamed.blend"
        bpy.ops.wm.save_as_mainfile(filepath=str(path))
        r = subprocess.run([sys.executable, "-m", "kinect_retarget", "info", "--rig", str(path), "--armature",
                            obj.name, "--json"],
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        info = json.loads(r.stdout.strip().splitlines()[-1])
        assert info["preset"] == "structure" and info["bones"] == 706
        assert {back[b]: j for b, j in info["mapping"].items()} == PRESETS["rigify"]
        torso = next(b for b, o in back.items() if o == "torso")
        assert info["found"]["HipCenter"].startswith(torso)
        assert any("control rig" in n for n in info["notes"])


def test_rigify_rig_generated_in_a_t_pose_renamed_maps_as_its_preset(bpy_empty, tmp_path):
    """The metarig's arms raised to horizontal before generating (the stock metarig's hang about 29° down)."""
    import addon_utils
    from mathutils import Matrix

    from kinect_retarget.blender.io.rig_reader import target_rig_from_object
    bpy = bpy_empty
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    bpy.ops.object.mode_set(mode="EDIT")
    bones = bpy.context.object.data.edit_bones
    for side, sign in (("L", 1), ("R", -1)):
        arm = bones[f"upper_arm.{side}"]
        down = np.arctan2(arm.head.z - arm.tail.z, abs(arm.tail.x - arm.head.x))
        turn = Matrix.Translation(arm.head) @ Matrix.Rotation(-sign * down, 4, "Y") @ Matrix.Translation(-arm.head)
        chain = [arm] + list(arm.children_recursive)
        moved = [(turn @ b.head, turn @ b.tail) for b in chain]  # first: a connected child shares its parent's tail
        for b, (head, tail) in zip(chain, moved):
            b.head, b.tail = head, tail
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.pose.rigify_generate()
    path = tmp_path / "rigify_t.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    obj, back = _open(bpy, path, 9)
    arm = obj.data.bones[next(b for b, o in back.items() if o == "upper_arm_fk.L")]
    assert abs(arm.tail_local.z - arm.head_local.z) < 1e-3   # the arm is level
    rig = target_rig_from_object(obj)
    used, mapping = build_mapping("auto", rig.bone_names, None, rig)
    assert used == "structure" and {back[b]: j for b, j in mapping.items()} == PRESETS["rigify"]


def test_rigify_rig_generated_from_the_basic_human_renamed_maps_as_its_preset(bpy_empty):
    """Rigify's other human metarig (Basic Human: no face, no fingers; 222 generated bones)."""
    import addon_utils

    from kinect_retarget.blender.io.rig_reader import fk_switch_bones, target_rig_from_object
    bpy = bpy_empty
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_basic_human_metarig_add()
    meta = bpy.context.object
    bpy.ops.pose.rigify_generate()
    obj = next(o for o in bpy.data.objects if o.type == "ARMATURE" and o != meta)
    assert len(obj.data.bones) == 222
    back = rename_bones(obj, 8)
    rig = target_rig_from_object(obj)
    used, mapping = build_mapping("auto", rig.bone_names, None, rig)
    assert used == "structure" and {back[b]: j for b, j in mapping.items()} == PRESETS["rigify"]
    assert sorted(back[b] for b in fk_switch_bones(obj)) == sorted(RIGIFY_FK_SWITCHES)


def test_sidebar_fills_the_table_of_the_renamed_control_rig(registered, rigify_rig_path):
    bpy = registered
    obj, back = _open(bpy, rigify_rig_path, 7)
    s = bpy.context.scene.kinect_retarget
    s.target = obj
    assert bpy.ops.kinect_retarget.mapping_from_preset() == {"FINISHED"}
    assert {back[row.bone]: row.joint for row in s.mapping if row.enabled} == PRESETS["rigify"]


def _bake(bpy, path, seed, take, options=None):
    """Bake `take` (preset auto; default options unless given); the keys by original bone name and Blender's
    evaluation of every deform bone at a few frames."""
    from kinect_retarget.blender.bake_take import bake_take
    from kinect_retarget.core.pipeline import RetargetSettings
    obj, back = _open(bpy, path, seed)
    res = bake_take(obj, take, preset="auto", settings=RetargetSettings(filter="none", fps=take.rate),
                    options=options)
    keys = {back[b]: res.motion.quats[:, k] for k, b in enumerate(res.motion.bone_names)}
    from bpy_extras import anim_utils
    switches = {}
    ad = obj.animation_data
    for fc in anim_utils.action_get_channelbag_for_slot(ad.action, ad.action_slot).fcurves:
        if fc.data_path.endswith('["IK_FK"]'):
            bone = fc.data_path.split('"')[1]
            switches[back[bone]] = fc.keyframe_points[0].co[1]
    deform = sorted(back[b.name] for b in obj.data.bones if b.use_deform or back[b.name] == "root")
    posed = []
    for f in (res.frame_range[0], sum(res.frame_range) // 2, res.frame_range[1]):
        bpy.context.scene.frame_set(f)
        pose = {back[pb.name]: np.array(pb.matrix) for pb in obj.pose.bones}
        posed.append(np.array([pose[n] for n in deform]))
    return res.preset, keys, switches, deform, np.array(posed)


@pytest.mark.parametrize("take_name,root_motion", [("kinect_v1_cmu_131_03_hop", False),
                                                    ("kinect_v1_cmu_131_03_hop", True),
                                                    ("kinect_v2_ges01_wavehand", False)],
                         ids=["default", "root-motion", "v2-hands"])
def test_bake_onto_the_renamed_rig_equals_the_bake_onto_the_original(bpy_empty, rigify_rig_path, take_name,
                                                                      root_motion):
    """Default options (feet locked; on a Kinect v2 take the hands too: thumb roll and finger bend on the
    finger controls, found by structure on the renamed rig), and with root motion: the renamed rig's root is
    found as the bone its torso follows by constraints, and carries the same travel as the preset's `root`."""
    from kinect_retarget.core.bake_options import BakeOptions
    from kinect_retarget.core.quat import angle_between, from_matrix
    from kinect_retarget.takes import load_take
    take = load_take(SAMPLES / f"{take_name}.krtake").slice(slice(0, 40))
    options = BakeOptions(root_motion=root_motion)
    preset, keys, switches, deform, posed = _bake(bpy_empty, rigify_rig_path, None, take, options)
    preset2, keys2, switches2, deform2, posed2 = _bake(bpy_empty, rigify_rig_path, 11, take, options)
    assert ("root" in keys) == root_motion
    assert ("f_index.02.L" in keys) == ("v2" in take_name)   # the hands bend the fingers
    assert (preset, preset2) == ("rigify", "structure")
    assert set(keys2) == set(keys) and switches2 == switches and len(switches) == 4 and deform2 == deform
    worst_key = max(float(np.degrees(angle_between(keys[b], keys2[b])).max()) for b in keys)
    assert worst_key < 1e-4, worst_key
    rot = lambda m: from_matrix(m[..., :3, :3] / np.linalg.norm(m[..., :3, :3], axis=-2, keepdims=True))  # noqa: E731
    worst_deform = float(np.degrees(angle_between(rot(posed), rot(posed2))).max())
    assert worst_deform < 1e-4, worst_deform
    assert np.abs(posed[..., :3, 3] - posed2[..., :3, 3]).max() < 1e-6
    print(f"renamed vs original bake: keys {worst_key:.2e} deg, {len(deform)} deform bones and root {worst_deform:.2e} deg")


def test_numpy_fixture_is_the_generated_rig(bpy_empty, rigify_rig_path):
    """tests/data/rigs/rigify_generated.json (the numpy tests' copy of this rig) is what Blender generates;
    KR_WRITE_RIGIFY_FIXTURE=1 writes it anew."""
    import os

    from kinect_retarget.blender.io.rig_reader import target_rig_from_object
    from tests.rigs.control_rigs import RIGIFY_FIXTURE, rig_record
    obj, _ = _open(bpy_empty, rigify_rig_path)
    rig = target_rig_from_object(obj)
    record = rig_record(rig.bone_names, rig.parents, rig.heads, rig.tails, rig.links)
    if os.environ.get("KR_WRITE_RIGIFY_FIXTURE"):
        RIGIFY_FIXTURE.parent.mkdir(parents=True, exist_ok=True)
        RIGIFY_FIXTURE.write_text(json.dumps(record, separators=(",", ":")) + "\n", encoding="utf-8")
    stored = json.loads(RIGIFY_FIXTURE.read_text(encoding="utf-8"))
    for key in ("names", "parents", "deform", "shaped", "constraints"):
        assert stored[key] == record[key], key
    for key in ("heads", "tails"):
        assert np.abs(np.array(stored[key]) - np.array(record[key])).max() < 1e-4, key
