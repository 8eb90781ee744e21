"""BVH reader: the real CMU and MakeHuman files, an independent FK check, the Kinect conversion, bad files."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V1, TRACKED
from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import bvh

CMU = {  # file: (frames, duration s, naming family), from data/README.md
    "01_01.bvh": (2752, 22.9, "cmu_motionbuilder"),
    "131_01.bvh": (994, 8.3, "cmu_3dsmax"),
    "131_02.bvh": (1247, 10.4, "cmu_3dsmax"),
    "131_03.bvh": (1102, 9.2, "cmu_3dsmax"),
}
CMU_UNIT = 0.0254 / 0.45


@pytest.fixture(scope="module")
def jump(data_dir):
    return bvh.read_bvh_skeleton(data_dir / "mocap_bvh" / "01_01.bvh")


def _raw_motion_line(path, frame):
    lines = path.read_text().splitlines()
    first = next(i for i, line in enumerate(lines) if line.lower().startswith("frame time")) + 1
    return np.array(lines[first + frame].split(), dtype=float)


@pytest.mark.parametrize("name", sorted(CMU))
def test_cmu_files_read_as_kinect_v1_takes(data_dir, name):
    frames, duration, family = CMU[name]
    take = bvh.read(data_dir / "mocap_bvh" / name)
    assert take.skeleton is KINECT_V1
    assert take.source_format == "bvh"
    assert take.frame_count == frames
    assert take.rate == 120.0
    assert take.duration == pytest.approx(duration, abs=0.05)
    assert np.all(take.states == TRACKED)
    assert take.metadata["bvh_family"] == family
    assert take.metadata["bvh_units_to_metres"] == pytest.approx(CMU_UNIT)
    # A person in front of a Kinect: never closer than the sensor can see, head above hips above feet.
    k = KINECT_V1.index
    assert take.positions[..., 2].min() >= bvh.MIN_RANGE - 1e-9
    assert np.all(take.positions[:, k("Head"), 1] > take.positions[:, k("HipCenter"), 1])
    assert np.median(take.positions[:, k("HipCenter"), 1] - take.positions[:, k("AnkleLeft"), 1]) \
        == pytest.approx(0.85, abs=0.12)


def test_root_position_matches_raw_text(data_dir, jump):
    path = data_dir / "mocap_bvh" / "01_01.bvh"
    for frame in (0, 1000, 2751):
        raw = _raw_motion_line(path, frame)
        np.testing.assert_allclose(jump.values[frame], raw)
        np.testing.assert_allclose(jump.positions[frame, jump.skeleton.index("Hips")], raw[:3])
    assert jump.values.shape == (2752, 96)


def _reference_fk(motion, joint, frame):
    """Slow, independent FK: walk the chain with one rotation matrix per channel."""
    sk = motion.skeleton
    chain = []
    j = sk.index(joint)
    while j >= 0:
        chain.append(j)
        j = int(sk.parents[j])
    rot, pos = np.eye(3), np.zeros(3)
    for j in reversed(chain):
        local_r, trans = np.eye(3), sk.offsets[j].copy()
        for c_i, name in enumerate(sk.channels[j]):
            v = motion.values[frame, sk.first_channel[j] + c_i]
            axis = "XYZ".index(name[0])
            if name.endswith("position"):
                trans[axis] = v if sk.parents[j] < 0 else trans[axis] + v
                continue
            c, s = np.cos(np.radians(v)), np.sin(np.radians(v))
            m = {0: [[1, 0, 0], [0, c, -s], [0, s, c]],
                 1: [[c, 0, s], [0, 1, 0], [-s, 0, c]],
                 2: [[c, -s, 0], [s, c, 0], [0, 0, 1]]}[axis]
            local_r = local_r @ np.array(m)
        pos = pos + rot @ trans
        rot = rot @ local_r
    return pos, rot


@pytest.mark.parametrize("joint", ["LeftHand", "RightToeBase", "Head_end", "LThumb_end"])
def test_forward_kinematics_matches_reference(jump, joint, rng):
    from kinect_retarget.core import quat
    j = jump.skeleton.index(joint)
    for frame in rng.integers(0, jump.frame_count, size=4):
        pos, rot = _reference_fk(jump, joint, int(frame))
        np.testing.assert_allclose(jump.positions[frame, j], pos, atol=1e-9)
        np.testing.assert_allclose(quat.to_matrix(jump.rotations[frame, j]), rot, atol=1e-9)


def test_bone_lengths_are_preserved_every_frame(jump):
    sk = jump.skeleton
    child = np.flatnonzero(sk.parents >= 0)
    lengths = np.linalg.norm(jump.positions[:, child] - jump.positions[:, sk.parents[child]], axis=-1)
    np.testing.assert_allclose(lengths, np.broadcast_to(np.linalg.norm(sk.offsets[child], axis=-1),
                                                          lengths.shape), atol=1e-9)


def test_frame0_tpose_faces_the_virtual_kinect(data_dir):
    take = bvh.read(data_dir / "mocap_bvh" / "01_01.bvh", min_range=None)
    p = take.positions[0]
    k = KINECT_V1.index
    # Performer's left hand is on the sensor's right: Kinect -X. Arms out level with the shoulders.
    assert p[k("HandLeft"), 0] < -0.6 and p[k("HandRight"), 0] > 0.6
    assert abs(p[k("HandLeft"), 1] - p[k("ShoulderLeft"), 1]) < 0.1
    # Hips 3 m in front of the sensor, sensor 0.8 m above the floor, toes pointing at the sensor.
    assert np.hypot(p[k("HipCenter"), 0], p[k("HipCenter"), 2]) == pytest.approx(3.0, abs=1e-6)
    assert p[k("FootLeft"), 2] < p[k("AnkleLeft"), 2]
    floor = take.metadata["virtual_camera"]["height_m"]
    assert p[k("AnkleLeft"), 1] == pytest.approx(-floor + 0.08, abs=0.05)
    # The jumps go toward the sensor: without the range guard they pass behind it.
    assert take.positions[..., 2].min() < 0


def test_makehuman_pose_decimetres_z_up(data_dir):
    for name in ("tpose.bvh", "benchmark.bvh"):
        motion = bvh.read_bvh_skeleton(data_dir / "meshes" / "makehuman" / name)
        assert motion.family == "makehuman"
        assert motion.units_to_metres == 0.1
        assert (motion.up_axis, motion.up_sign) == (2, 1.0)
        assert motion.frame_count == 1
    assert len(motion.skeleton.names) >= 163
    take = bvh.read(data_dir / "meshes" / "makehuman" / "tpose.bvh")
    k = KINECT_V1.index
    p = take.positions[0]
    assert p[k("Head"), 1] - p[k("AnkleLeft"), 1] == pytest.approx(1.5, abs=0.12)
    assert p[k("HandLeft"), 0] < -0.6  # T-pose, facing the sensor
    assert take.rate == 24.0


def test_explicit_scale_and_unit_heuristic(data_dir, tmp_path):
    src = (data_dir / "mocap_bvh" / "131_01.bvh").read_text()
    take = bvh.read(data_dir / "mocap_bvh" / "131_01.bvh", scale=0.05, min_range=None)
    ref = bvh.read(data_dir / "mocap_bvh" / "131_01.bvh", min_range=None)
    k = KINECT_V1.index
    spine = lambda t: np.linalg.norm(t.positions[:, k("Head")] - t.positions[:, k("HipCenter")], axis=-1)
    np.testing.assert_allclose(spine(take), spine(ref) * 0.05 / CMU_UNIT)
    # Unknown naming (joints renamed) still reads its skeleton; units come from the rest height.
    (tmp_path / "prefixed.bvh").write_text(src.replace("JOINT ", "JOINT x_").replace("ROOT Hips", "ROOT x_Hips"))
    assert bvh.read_bvh_skeleton(tmp_path / "prefixed.bvh").family == "cmu_3dsmax"  # shared prefix dropped
    renamed = src.replace("JOINT ", "JOINT j").replace("ROOT Hips", "ROOT jHips")
    (tmp_path / "renamed.bvh").write_text(renamed)
    motion = bvh.read_bvh_skeleton(tmp_path / "renamed.bvh")
    assert motion.family is None and motion.units_to_metres == pytest.approx(CMU_UNIT)
    # names decide nothing: the renamed skeleton maps by structure onto the same joints
    np.testing.assert_allclose(bvh.read(tmp_path / "renamed.bvh", min_range=None).positions, ref.positions)
    # a skeleton that is no humanoid (one long chain) is refused with the reason
    lines = ["HIERARCHY", "ROOT a", "{", "OFFSET 0 0 0", "CHANNELS 6 Xposition Yposition Zposition Zrotation "
             "Yrotation Xrotation"] + sum([[f"JOINT s{i}", "{", "OFFSET 0 10 0", "CHANNELS 3 Zrotation Yrotation "
                                           "Xrotation"] for i in range(6)], []) + \
        ["End Site", "{", "OFFSET 0 10 0", "}"] + ["}"] * 7 + ["MOTION", "Frames: 2", "Frame Time: 0.04"] + \
        [" ".join(["0"] * 24)] * 2
    (tmp_path / "snake.bvh").write_text("\n".join(lines) + "\n")
    with pytest.raises(TakeError, match=r"snake\.bvh: BVH skeleton not recognised as a humanoid: no node where"):
        bvh.read(tmp_path / "snake.bvh")
    with pytest.raises(TakeError, match="scale must be a positive"):
        bvh.read(data_dir / "mocap_bvh" / "131_01.bvh", scale=-1.0)


def test_looks_like(data_dir):
    head = (data_dir / "mocap_bvh" / "131_02.bvh").read_bytes()[:4096]
    assert bvh.looks_like(head)
    assert bvh.looks_like(b"\xef\xbb\xbfHIERARCHY\r\nROOT Hips")
    assert not bvh.looks_like((data_dir / "kinect_v2" / "joints.csv").read_bytes()[:4096])


def _corrupt(tmp_path, data_dir, name, edit):
    lines = (data_dir / "mocap_bvh" / "131_03.bvh").read_text().splitlines(keepends=True)
    path = tmp_path / name
    path.write_text("".join(edit(lines)))
    return path


def _set_token(line, i, value):
    tokens = line.split()
    tokens[i] = value
    return " ".join(tokens) + "\n"


CORRUPTIONS = {
    # name: (edit of the line list, expected message pattern)
    "truncated.bvh": (lambda ls: ls[:500] + [ls[500][:40]], r"truncated\.bvh:501: expected 96 values, found"),
    "cut_short.bvh": (lambda ls: ls[:500], r"cut_short\.bvh: 'Frames: 1102' but only 313 motion lines"),
    "columns.bvh": (lambda ls: ls[:300] + [ls[300].rstrip() + " 1.0\n"] + ls[301:],
                    r"columns\.bvh:301: expected 96 values, found 97"),
    "garbage.bvh": (lambda ls: ls[:250] + [_set_token(ls[250], 3, "hello")] + ls[251:],
                    r"garbage\.bvh:251: non-numeric value 'hello'"),
    "no_motion.bvh": (lambda ls: ls[:150], r"no_motion\.bvh: BVH file has no MOTION section"),
    "unbalanced.bvh": (lambda ls: ls[:2] + ls[3:], r"unbalanced\.bvh:\d+: "),
    "channels.bvh": (lambda ls: [l.replace("CHANNELS 3 Zrotation Yrotation Xrotation",
                                           "CHANNELS 3 Zrotation Yrotation", 1) for l in ls],
                     r"channels\.bvh:\d+: CHANNELS says 3 but lists 2"),
}


@pytest.mark.parametrize("name", sorted(CORRUPTIONS))
def test_corrupt_files_name_file_and_line(tmp_path, data_dir, name):
    edit, pattern = CORRUPTIONS[name]
    path = _corrupt(tmp_path, data_dir, name, edit)
    with pytest.raises(TakeError, match=pattern):
        bvh.read(path)


def test_empty_and_not_bvh(tmp_path):
    (tmp_path / "empty.bvh").write_bytes(b"  \n")
    with pytest.raises(TakeError, match=r"empty\.bvh: file is empty"):
        bvh.read(tmp_path / "empty.bvh")
    (tmp_path / "text.bvh").write_text("hello world\n")
    with pytest.raises(TakeError, match=r"text\.bvh:1: not a BVH file"):
        bvh.read(tmp_path / "text.bvh")
    with pytest.raises(TakeError, match="cannot read"):
        bvh.read(tmp_path / "missing.bvh")


RENAMES = {  # CMU MotionBuilder name -> the same joint in other rig families (Left side; Right alike)
    "biped": {"Hips": "Bip001 Pelvis", "Spine1": "Bip001 Spine1", "Head": "Bip001 Head",
              "{L}Arm": "Bip001 {l} UpperArm", "{L}ForeArm": "Bip001 {l} Forearm", "{L}Hand": "Bip001 {l} Hand",
              "{s}Fingers": "Bip001 {l} Finger2", "{L}UpLeg": "Bip001 {l} Thigh", "{L}Leg": "Bip001 {l} Calf",
              "{L}Foot": "Bip001 {l} Foot", "{L}ToeBase": "Bip001 {l} Toe0"},
    "daz": {"Hips": "hip", "LowerBack": "abdomen", "Spine1": "chest", "Head": "head", "{L}Arm": "{d}Shldr",
            "{L}ForeArm": "{d}ForeArm", "{L}Hand": "{d}Hand", "{s}Fingers": "{d}Mid1", "{L}UpLeg": "{d}Thigh",
            "{L}Leg": "{d}Shin", "{L}Foot": "{d}Foot", "{L}ToeBase": "{d}Toe"},
    "rigify": {"Hips": "DEF-spine", "Spine1": "DEF-spine.002", "Head": "DEF-spine.006",
               "{L}Arm": "DEF-upper_arm.{s}", "{L}ForeArm": "DEF-forearm.{s}", "{L}Hand": "DEF-hand.{s}",
               "{s}Fingers": "DEF-f_middle.01.{s}", "{L}UpLeg": "DEF-thigh.{s}", "{L}Leg": "DEF-shin.{s}",
               "{L}Foot": "DEF-foot.{s}", "{L}ToeBase": "DEF-toe.{s}"},
    "cmu_motionbuilder": {n: f"Character1_{n}" for n in ("Hips", "LowerBack", "Spine", "Spine1", "Neck", "Neck1",
                                                          "Head", "{L}Arm", "{L}ForeArm", "{L}Hand",
                                                          "{L}FingerBase", "{s}Fingers", "{s}Thumb",
                                                          "{L}UpLeg", "{L}Leg", "{L}Foot", "{L}ToeBase",
                                                          "{L}Shoulder", "{s}HipJoint")},
    "mixamo": {n: f"mixamorig:{n}" for n in ("Hips", "Spine", "Spine1", "Head", "{L}Arm", "{L}ForeArm",
                                            "{L}Hand", "{L}UpLeg", "{L}Leg", "{L}Foot", "{L}ToeBase")}
    | {"{s}Fingers": "mixamorig:{L}HandMiddle1", "{L}FingerBase": "mixamorig:{L}HandRoot"},
}
SAME_DEFINITION = ("HipCenter", "ShoulderCenter", "ShoulderLeft", "ElbowLeft", "WristLeft", "HandLeft",
                   "HipLeft", "KneeLeft", "AnkleLeft", "FootLeft", "ShoulderRight", "WristRight", "FootRight")


@pytest.mark.parametrize("family", sorted(RENAMES))
def test_other_rig_families_by_renaming_real_mocap(data_dir, tmp_path, family):
    import re
    table = {}
    for src, dst in RENAMES[family].items():
        for side, s, l, d in (("Left", "L", "L", "l"), ("Right", "R", "R", "r")):
            table[src.format(L=side, s=s)] = dst.format(L=side, s=s, l=l, d=d)
    lines = (data_dir / "mocap_bvh" / "01_01.bvh").read_text().splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("Frame Time")) + 1
    frames = 240  # enough motion; keeps the test fast
    text = "\n".join(line if not line.startswith("Frames:") else f"Frames: {frames}"
                     for line in lines[:first + frames]) + "\n"
    (tmp_path / "original.bvh").write_text(text)
    text = re.sub(r"^(\s*(?:ROOT|JOINT) )(\S+)\s*$", lambda m: m.group(1) + table.get(m.group(2), m.group(2)),
                  text, flags=re.M)
    (tmp_path / "renamed.bvh").write_text(text)
    motion = bvh.read_bvh_skeleton(tmp_path / "renamed.bvh")
    assert motion.family == family
    assert motion.units_to_metres == pytest.approx(CMU_UNIT)  # from the rest height: CMU units
    take = bvh.read(tmp_path / "renamed.bvh", min_range=None)
    ref = bvh.read(tmp_path / "original.bvh", min_range=None)
    idx = [KINECT_V1.index(j) for j in SAME_DEFINITION]
    np.testing.assert_allclose(take.positions[:, idx], ref.positions[:, idx], atol=1e-9)


def test_virtual_kinect_reproduces_the_take(jump, data_dir):
    """Other code projects any BVH joint with the same sensor as the take (e.g. fingertips to 2D)."""
    take = bvh.read(data_dir / "mocap_bvh" / "01_01.bvh")
    cam = bvh.virtual_kinect(jump)
    np.testing.assert_allclose(cam.to_kinect(bvh.kinect_joints_lab(jump)), take.positions, atol=1e-12)
    assert cam.as_dict()["distance_m"] == pytest.approx(take.metadata["virtual_camera"]["distance_m"])
    everything = cam.to_kinect(jump.positions_m)
    assert everything[..., 2].min() > 0.9  # every BVH joint, end sites included, stays in front
    np.testing.assert_allclose(cam.rotation @ cam.rotation.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(cam.rotation) == pytest.approx(1.0)  # a rotation: nothing mirrored
