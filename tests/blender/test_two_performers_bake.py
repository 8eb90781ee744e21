"""Two performers of one take, each baked onto its own rig from the CLI: `--body all` (a generated rig per
body), `--rig FILE --armature NAME --body N` pairs (in any order) and `--rig FILE --body N` once per body (each
rig in its own file); each rig follows its own body's limbs and not the other's."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from kinect_retarget.core.conventions import kinect_to_blender
from tests.takes.two_performers import performers, write_two_person_ntu


def _cli(*args):
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", *map(str, args)], capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def _limb_errors(bpy, obj, take, first_frame):
    """Per keyed frame, the mean angle (degrees) between each bone and its limb in `take` (the generated
    rig's bone J runs from J's parent joint to joint J; filter none, keys on the take's samples)."""
    sk = take.skeleton
    p = kinect_to_blender(take.positions)
    errs = []
    for i in range(0, take.frame_count, 5):
        bpy.context.scene.frame_set(first_frame + i)
        for j, name in enumerate(sk.joints):
            if sk.parents[j] < 0 or name not in obj.pose.bones:
                continue
            pb = obj.pose.bones[name]
            d = np.array(obj.matrix_world @ pb.tail) - np.array(obj.matrix_world @ pb.head)
            src = p[i, j] - p[i, sk.parents[j]]
            if np.linalg.norm(src) < 1e-6:
                continue
            cos = d @ src / np.linalg.norm(d) / np.linalg.norm(src)
            errs.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    return float(np.mean(errs))


@pytest.fixture
def two_person_take(data_dir, tmp_path):
    return write_two_person_ntu(data_dir, tmp_path / "S001C001P001R001A050.skeleton")


def test_body_all_bakes_each_body_onto_a_generated_rig(bpy_empty, data_dir, tmp_path, two_person_take):
    bpy = bpy_empty
    out = tmp_path / "duo.blend"
    rc, stdout, stderr = _cli("bake", two_person_take, "--out", out, "--body", "all", "--filter", "none",
                              "--feet", "off",  # limb directions as the solver gives them
                              "--fps", 30)
    assert rc == 0, stderr
    result = json.loads(stdout.strip().splitlines()[-1])
    assert [p["body"] for p in result["performers"]] == [0, 1]
    assert [p["armature"] for p in result["performers"]] == ["KinectRig_body0", "KinectRig_body1"]
    bpy.ops.wm.open_mainfile(filepath=str(out))
    first, second = performers(data_dir)
    second.positions[..., 0] += 1.0
    start = result["performers"][0]["frame_range"][0]
    a, b = bpy.data.objects["KinectRig_body0"], bpy.data.objects["KinectRig_body1"]
    assert _limb_errors(bpy, a, first, start) < 0.5 and _limb_errors(bpy, b, second, start) < 0.5
    assert _limb_errors(bpy, a, second, start) > 5 and _limb_errors(bpy, b, first, start) > 5


def test_armature_body_pairs_bake_onto_the_rigs_of_a_file(bpy_empty, data_dir, tmp_path, two_person_take):
    from kinect_retarget.blender.bake_take import new_generated_rig
    bpy = bpy_empty
    first, second = performers(data_dir)
    for name in ("Alice", "Bob"):
        new_generated_rig(bpy.context.scene, first, name)
    rigs = tmp_path / "rigs.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(rigs))
    out = tmp_path / "duo.blend"
    # pairs in order: Bob dances body 1, Alice body 0
    rc, stdout, stderr = _cli("bake", two_person_take, "--out", out, "--rig", rigs, "--armature", "Bob",
                              "--body", 1, "--armature", "Alice", "--body", 0, "--filter", "none",
                              "--preset", "kinect", "--set-scene-fps", "--fps", 30, "--feet", "off")
    assert rc == 0, stderr
    result = json.loads(stdout.strip().splitlines()[-1])
    assert [(p["armature"], p["body"]) for p in result["performers"]] == [("Bob", 1), ("Alice", 0)]
    bpy.ops.wm.open_mainfile(filepath=str(out))
    second.positions[..., 0] += 1.0
    start = result["performers"][0]["frame_range"][0]
    alice, bob = bpy.data.objects["Alice"], bpy.data.objects["Bob"]
    assert _limb_errors(bpy, alice, first, start) < 0.5 and _limb_errors(bpy, bob, second, start) < 0.5
    assert _limb_errors(bpy, bob, first, start) > 5


def test_one_rig_file_per_body(bpy_empty, data_dir, tmp_path, two_person_take):
    """`--rig A.blend --body 1 --rig B.blend --body 0`: each performer's rig from its own file (both armatures
    named "rig": the second comes in as "rig.001"), baked into one .blend, each following its own body."""
    from kinect_retarget.blender.bake_take import new_generated_rig
    bpy = bpy_empty
    first, second = performers(data_dir)
    files = [tmp_path / "a.blend", tmp_path / "b.blend"]
    for path in files:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        new_generated_rig(bpy.context.scene, first, "rig")
        bpy.ops.wm.save_as_mainfile(filepath=str(path))
    out = tmp_path / "duo.blend"
    rc, stdout, stderr = _cli("bake", two_person_take, "--out", out, "--rig", files[0], "--body", 1,
                              "--rig", files[1], "--body", 0, "--filter", "none", "--preset", "kinect",
                              "--set-scene-fps", "--fps", 30, "--feet", "off")
    assert rc == 0, stderr
    result = json.loads(stdout.strip().splitlines()[-1])
    assert [(p["armature"], p["body"]) for p in result["performers"]] == [("rig", 1), ("rig.001", 0)]
    bpy.ops.wm.open_mainfile(filepath=str(out))
    second.positions[..., 0] += 1.0
    start = result["performers"][0]["frame_range"][0]
    one, zero = bpy.data.objects["rig"], bpy.data.objects["rig.001"]
    assert _limb_errors(bpy, one, second, start) < 0.5 and _limb_errors(bpy, zero, first, start) < 0.5
    assert _limb_errors(bpy, one, first, start) > 5 and _limb_errors(bpy, zero, second, start) > 5
    assert "b" in bpy.data.collections  # the second file's objects, in a collection named after it
    rc, _, err = _cli("bake", two_person_take, "--out", tmp_path / "x.blend", "--rig", files[0], "--rig",
                      files[1], "--body", 0)
    assert rc == 2 and "2 --rig files need as many --body" in err
    rc, _, err = _cli("bake", two_person_take, "--out", tmp_path / "x.blend", "--rig", files[0], "--rig",
                      tmp_path / "missing.blend", "--body", 0, "--body", 1)
    assert rc != 0 and "missing.blend: rig file not found" in err
    rc, _, err = _cli("live", "--source", f"take:{two_person_take}", "--seconds", 1, "--rig", files[0], "--rig",
                      files[1], "--body", 0, "--body", 1)
    assert rc == 2 and "live: one --rig file" in err


def test_bad_performer_arguments_are_named(tmp_path, two_person_take, data_dir):
    rc, _, err = _cli("bake", two_person_take, "--out", tmp_path / "x.blend", "--body", 2)
    assert rc == 2 and "no body 2" in err
    rc, _, err = _cli("bake", two_person_take, "--out", tmp_path / "x.blend", "--rig", tmp_path / "r.blend",
                      "--body", 0, "--body", 1, "--armature", "A")
    assert rc == 2 and "2 bodies need 2 --armature" in err
    rc, _, err = _cli("bake", two_person_take, "--out", tmp_path / "x.fbx", "--body", "all")
    assert rc == 2 and "one .blend" in err
    rc, _, err = _cli("bake", data_dir / "kinect_v2" / "Ges01_wavehand.csv", "--out", tmp_path / "x.blend",
                      "--body", 1)
    assert rc == 2 and "no body 1" in err
    rc, _, err = _cli("bake", data_dir / "kinect_v2" / "Ges01_wavehand.csv", "--out", tmp_path / "x.blend",
                      "--armature", "Nope")  # one body, no --rig: the name would be ignored
    assert rc == 2 and "without --rig" in err


def test_live_command_drives_a_rig_per_body(tmp_path, two_person_take):
    rc, stdout, stderr = _cli("live", "--source", f"take:{two_person_take}", "--seconds", 60, "--speed", 4,
                              "--body", "all", "--filter", "none", "--record", tmp_path / "duo.krtake",
                              "--out", tmp_path / "duo.blend")
    assert rc == 0, stderr
    result = json.loads(stdout.strip().splitlines()[-1])
    assert [(p["armature"], p["body"]) for p in result["performers"]] == [("KinectRig_body0", 0),
                                                                          ("KinectRig_body1", 1)]
    assert all(p["action"] and p["applied"] > 0 and p["error"] is None for p in result["performers"])
    from kinect_retarget.takes import load_take
    for rec, body in (("duo.krtake", 0), ("duo_body1.krtake", 1)):  # each body recorded on its own
        got, want = load_take(tmp_path / rec), load_take(two_person_take, body=body)
        np.testing.assert_allclose(got.positions[-1], want.positions[-1], atol=2e-5)
    rc, _, err = _cli("live", "--source", "osc:0", "--seconds", 1, "--body", "all")
    assert rc == 2 and "needs a take" in err
