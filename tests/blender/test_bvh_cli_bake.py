"""A real Z-up, millimetre BVH without hands or feet (video2bvh) through the CLI `bake` and Blender itself:
the saved rig stands upright at human size, its limbs follow the file's joints, and the guesses are reported."""
import subprocess
import sys
from pathlib import Path

import numpy as np

from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.takes import load_take

BVH = Path(__file__).resolve().parents[1] / "data" / "bvh" / "video2bvh_dance.bvh"


def _bake(tmp_path, *extra):
    out = tmp_path / "dance.blend"
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(BVH), "--out", str(out),
                        "--filter", "none", "--feet", "off", *extra], capture_output=True, text=True)
    return r, out


def test_cli_bake_of_a_z_up_millimetre_bvh_stands_upright(bpy_empty, tmp_path):
    bpy = bpy_empty
    r, out = _bake(tmp_path)
    assert r.returncode == 0, r.stderr
    assert "BVH read in millimetres" in r.stdout and "+Z up" in r.stdout and "warning" not in r.stderr
    bpy.ops.wm.open_mainfile(filepath=str(out))
    obj = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    take = load_take(BVH)
    p = kinect_to_blender(take.positions)
    scene = bpy.context.scene

    def world(bone, end):
        pb = obj.pose.bones[bone]
        return np.array(obj.matrix_world @ (pb.tail if end == "tail" else pb.head))

    errs, heights = [], []
    for i in range(0, take.frame_count, 25):
        scene.frame_set(scene.frame_start + i)
        head, hips = world("Head", "tail"), world("HipCenter", "head")
        ankles = [world(f"Ankle{s}", "tail") for s in ("Left", "Right")]
        assert head[2] > hips[2] > max(a[2] for a in ankles)
        heights.append(head[2] - min(world(f"Foot{s}", "tail")[2] for s in ("Left", "Right")))
        for a, b in (("ShoulderLeft", "ElbowLeft"), ("ElbowRight", "WristRight"), ("HipLeft", "KneeLeft"),
                     ("KneeRight", "AnkleRight")):
            src = p[i, take.skeleton.index(b)] - p[i, take.skeleton.index(a)]
            got = world(b, "tail") - world(b, "head")
            cos = src @ got / np.linalg.norm(src) / np.linalg.norm(got)
            errs.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    assert 1.3 <= np.percentile(heights, 90) <= 1.8
    assert max(errs) < 1.0


def test_cli_bake_scale_override_and_odd_size_warning(tmp_path):
    r, _ = _bake(tmp_path, "--scale", "0.01")
    assert r.returncode == 0, r.stderr
    assert "warning: the figure is 15.45 m tall with the unit 0.01 m per unit (given)" in r.stderr
    bad = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(BVH), "--out",
                          str(tmp_path / "x.blend"), "--scale", "-2"], capture_output=True, text=True)
    assert bad.returncode == 2 and "scale must be a positive number" in bad.stderr


def test_blender_bvh_export_reads_back_as_the_same_figure(tmp_path):
    """Blender's own BVH exporter (Z up, metres, full local translations on every joint, bones named after
    their tail joint) through `bake --out x.bvh`, read back: the same limbs as the source."""
    from kinect_retarget.takes import bvh
    from tests.takes import baked_figure
    src = BVH.parent / "mocapbank_sit_down.bvh"
    out = tmp_path / "exported.bvh"
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(src), "--out", str(out), "--filter",
                        "none", "--feet", "off", "--take-end", "59", "--range-unit", "frames"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    back = bvh.read(out, min_range=None)
    meta = back.metadata
    assert meta["bvh_unit"].startswith("metres") and meta["bvh_up_axis"] == "+Z"
    assert meta["bvh_position_channels"].startswith("position channels hold each joint's full local translation")
    source = bvh.read(src, min_range=None).slice(slice(0, 60))
    joints, samples = baked_figure.bake(back)
    assert baked_figure.heights(joints, back.skeleton)["upright"]
    assert baked_figure.limb_direction_errors(joints, samples, source).max() < 0.5


def test_bake_take_operator_scale_and_report(registered, capfd):
    from kinect_retarget.blender.bake_take import new_generated_rig
    bpy = registered
    obj = new_generated_rig(bpy.context.scene, load_take(BVH))
    bpy.context.view_layer.objects.active = obj
    capfd.readouterr()
    assert bpy.ops.kinect_retarget.bake_take(filepath=str(BVH), preset="kinect") == {"FINISHED"}
    out = capfd.readouterr()
    assert "BVH read in millimetres" in out.out + out.err and "m tall with the unit" not in out.out + out.err
    assert bpy.ops.kinect_retarget.bake_take(filepath=str(BVH), preset="kinect", scale=0.01) == {"FINISHED"}
    out = capfd.readouterr()
    assert "the figure is 15.45 m tall with the unit 0.01 m per unit (given)" in out.out + out.err
