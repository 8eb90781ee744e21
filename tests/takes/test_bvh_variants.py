"""One real file (Mixamo rig, centimetres) rewritten the ways other exporters write the same motion: every
variant reads as the same figure, bakes upright at 1.5-1.9 m and its limbs follow the source's joints."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1
from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import bvh
from tests.takes import baked_figure
from tests.takes import bvh_variants as bv

SOURCE = Path(__file__).resolve().parents[1] / "data" / "bvh" / "mixamo_freebvh.bvh"

VARIANTS = {  # name: (transform, write options, expected unit, up axis, position channels)
    "renamed": (bv.renamed, {}, "centimetres", "+Y", "root only"),
    "absolute_positions": (lambda f: f, {"absolute": True}, "centimetres", "+Y", "full local translation"),
    "x_along_bones": (bv.x_along_bones, {}, "centimetres", "+Y", "root only"),
    "z_up": (bv.z_up, {}, "centimetres", "+Z", "root only"),
    "z_up_x_along_absolute": (lambda f: bv.x_along_bones(bv.z_up(f)), {"absolute": True}, "centimetres", "+Z",
                              "full local translation"),
    "metres": (lambda f: bv.scaled(f, 0.01), {}, "metres", "+Y", "root only"),
    "millimetres": (lambda f: bv.scaled(f, 10.0), {}, "millimetres", "+Y", "root only"),
    "inches": (lambda f: bv.scaled(f, 1 / 2.54), {}, "inches", "+Y", "root only"),
    "no_hands": (bv.without_hands, {}, "centimetres", "+Y", "root only"),
    "reference_root": (bv.under_reference, {}, "centimetres", "+Y", "root only"),
    "joint_site_crlf": (bv.renamed, {"joint_site": True, "root_joint": True, "newline": "\r\n"},
                        "centimetres", "+Y", "root only"),
}
MODES = {"root only": "position channels on the root only",
         "full local translation": "position channels hold each joint's full local translation (OFFSET ignored)"}


@pytest.fixture(scope="module")
def source_figure():
    return bv.load(SOURCE)


@pytest.fixture(scope="module")
def reference():
    return bvh.read(SOURCE, min_range=None)


def _variant(tmp_path, source_figure, name):
    transform, options, *_ = VARIANTS[name]
    path = tmp_path / f"{name}.bvh"
    bv.write(transform(source_figure), path, **options)
    return path


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_variant_reads_as_the_same_figure(tmp_path, source_figure, reference, name):
    _, _, unit, up, mode = VARIANTS[name]
    take = bvh.read(_variant(tmp_path, source_figure, name), min_range=None)
    meta = take.metadata
    assert meta["bvh_unit"].startswith(unit) and meta["bvh_up_axis"] == up
    assert meta["bvh_position_channels"] == MODES[mode]
    assert 1.5 <= meta["bvh_standing_height_m"] <= 1.9 and "warnings" not in meta
    same = np.ones(len(KINECT_V1), dtype=bool)
    if name == "no_hands":
        hands = [KINECT_V1.index(j) for j in ("HandLeft", "HandRight")]
        same[hands] = False
        assert np.all(take.states[:, hands] == INFERRED)
    np.testing.assert_allclose(take.positions[:, same], reference.positions[:, same], atol=2e-5)


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_variant_bakes_upright_human_sized_following_the_source(tmp_path, source_figure, reference, name):
    take = bvh.read(_variant(tmp_path, source_figure, name), min_range=None)
    joints, samples = baked_figure.bake(take)
    fig = baked_figure.heights(joints, take.skeleton)
    assert fig["upright"] and 1.5 <= fig["head_to_foot_m"] <= 1.9
    assert baked_figure.limb_direction_errors(joints, samples, reference).max() < 0.5


def test_scale_overrides_the_guess_and_odd_sizes_warn(tmp_path, source_figure, reference):
    path = _variant(tmp_path, source_figure, "millimetres")
    take = bvh.read(path, scale=0.001, min_range=None)
    assert take.metadata["bvh_unit"].startswith("0.001 m per unit (given)") and "warnings" not in take.metadata
    np.testing.assert_allclose(take.positions, reference.positions, atol=2e-5)
    wrong = bvh.read(path, scale=0.01, min_range=None)  # a 17.6 m giant: read, but said out loud
    assert wrong.metadata["warnings"] == [(
        "the figure is 17.55 m tall with the unit 0.01 m per unit (given): outside 1-2.3 m; "
        "pass --scale (metres per file unit) to fix it")]


def test_layout_edge_cases(tmp_path, source_figure):
    one = bv.Figure(**{**source_figure.__dict__, "local": source_figure.local[:1],
                       "root_pos": source_figure.root_pos[:1]})
    bv.write(one, tmp_path / "pose.bvh")
    take = bvh.read(tmp_path / "pose.bvh", min_range=None)  # one frame bakes a pose
    assert take.frame_count == 1 and 1.5 <= take.metadata["bvh_standing_height_m"] <= 1.9
    joints, _ = baked_figure.bake(take)
    assert baked_figure.heights(joints, take.skeleton)["upright"]
    text = (tmp_path / "pose.bvh").read_text().split("MOTION")[0] + "MOTION\nFrames: 0\nFrame Time: 0.033\n"
    (tmp_path / "empty.bvh").write_text(text)
    with pytest.raises(TakeError, match=r"empty\.bvh: BVH file has no frames \('Frames: 0'\): nothing to bake"):
        bvh.read(tmp_path / "empty.bvh")


V2_NAMES = {"Hips": "SpineBase", "Spine1": "SpineMid", "Spine2": "SpineShoulder", "Neck": "Neck", "Head": "Head",
            **{f"{side}{a}": f"{b}{side}" for side in ("Left", "Right") for a, b in (
                ("Arm", "Shoulder"), ("ForeArm", "Elbow"), ("Hand", "Wrist"), ("HandMiddle1", "Hand"),
                ("UpLeg", "Hip"), ("Leg", "Knee"), ("Foot", "Ankle"), ("ToeBase", "Foot"))}}


def test_kinect_v2_named_bvh_maps_one_to_one(tmp_path, source_figure, reference):
    fig = bv.Figure(**{**source_figure.__dict__, "names": [
        V2_NAMES.get(n.split(":")[-1], n) for n in source_figure.names]})
    bv.write(fig, tmp_path / "v2.bvh")
    take = bvh.read(tmp_path / "v2.bvh", min_range=None)
    mapping = take.metadata["bvh_mapping"]
    v2 = {"HipCenter": "SpineBase", "Spine": "SpineMid", "ShoulderCenter": "SpineShoulder"}
    for joint in KINECT_V1.joints:
        assert mapping[joint] == f"{v2.get(joint, joint)} (Kinect name)"
    limbs = [KINECT_V1.index(j) for j in KINECT_V1.joints if j not in v2 and j != "Head"]  # the named joints
    np.testing.assert_allclose(take.positions[:, limbs], reference.positions[:, limbs], atol=2e-5)
