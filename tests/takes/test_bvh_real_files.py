"""Real BVH files from ten sources (tests/data/bvh/README.md): each maps by structure onto the Kinect
joints, with the right unit and up axis, and bakes an upright, human-sized figure that follows its joints."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, TRACKED
from kinect_retarget.takes import bvh
from tests.takes import baked_figure

DATA = Path(__file__).resolve().parents[1] / "data" / "bvh"

# file: (unit, up axis, {Kinect joint: the BVH joint(s) it must map to})
EXPECTED = {
    "cmu_01_01.bvh": ("CMU units", "+Y", {"ShoulderLeft": "LeftArm", "WristLeft": "LeftHand",
                                         "HipRight": "RightUpLeg", "FootRight": "RightToeBase"}),
    "cmu_131_03.bvh": ("CMU units", "+Y", {"ShoulderLeft": "LeftShoulder", "ElbowLeft": "LeftElbow",
                                          "KneeRight": "RightKnee", "FootLeft": "LeftToe"}),
    "mocapbank_sit_down.bvh": ("centimetres", "+Y", {"WristLeft": "LeftWrist", "HandLeft": "LeftWrist_end",
                                                 "ShoulderRight": "RightShoulder", "AnkleLeft": "LeftAnkle"}),
    "mixamo_freebvh.bvh": ("centimetres", "+Y", {"HandRight": "mixamorig:RightHandMiddle1",
                                                 "Head": "mixamorig:Head + mixamorig:HeadTop_End"}),
    "biovision_example.bvh": ("inches", "+Y", {"ShoulderLeft": "LeftUpArm", "ElbowLeft": "LeftLowArm",
                                               "WristLeft": "LeftHand", "KneeRight": "RightLowLeg"}),
    "video2bvh_dance.bvh": ("millimetres", "+Z", {"ShoulderLeft": "LeftArm", "WristRight": "RightHand",
                                                  "HandLeft": "-", "FootRight": "-", "Head": "Neck1 + Neck1_end"}),
    "pymo_walk_meredith.bvh": ("inches", "+Y", {"HandLeft": "LeftHand_End", "Spine": "Hips + Spine",
                                                "FootRight": "RightToeBase"}),
    "univrm_sample.bvh": ("centimetres", "+Y", {"ElbowRight": "RightForeArm", "HandLeft": "LeftHand_end"}),
    "blender_export_kinect_rig.bvh": ("metres", "+Z", {"ShoulderLeft": "ElbowLeft", "WristRight": "HandRight",
                                                       "HipLeft": "KneeLeft", "HandLeft": "HandLeft_end"}),
    "optitrack_arena_louise.bvh": ("centimetres", "+Y", {"ShoulderLeft": "LeftShoulder", "ElbowLeft": "LeftElbow",
                                                         "WristLeft": "LeftWrist", "HandLeft": "LeftWrist_end",
                                                         "KneeRight": "RightKnee", "FootRight": "RightAnkle_end"}),
    "kinect_openni_nite.bvh": ("centimetres", "+Y", {**{j: j for j in KINECT_V1.joints if j[:-4] in (
        "Shoulder", "Elbow", "Wrist", "Knee", "Ankle") or j.startswith("Hip") and j != "HipCenter"},
        "Head": "Head", "ShoulderCenter": "ShoulderCenter", "HandLeft": "WristLeft_end"}),
}


def test_every_shipped_file_is_listed():
    assert sorted(p.name for p in DATA.glob("*.bvh")) == sorted(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_real_file_maps_by_structure_with_unit_and_up(name):
    unit, up, joints = EXPECTED[name]
    take = bvh.read(DATA / name, min_range=None)
    meta = take.metadata
    assert meta["bvh_unit"].startswith(unit) and meta["bvh_up_axis"] == up
    assert 1.4 <= meta["bvh_standing_height_m"] <= 1.9 and "warnings" not in meta
    for joint, expected in joints.items():
        assert meta["bvh_mapping"][joint].split(" (")[0] == expected, (joint, meta["bvh_mapping"][joint])
    extrapolated = [KINECT_V1.index(j) for j, how in meta["bvh_mapping"].items() if how.startswith("- ")]
    assert np.all(take.states[:, extrapolated] == INFERRED)
    assert np.all(np.delete(take.states, extrapolated, axis=1) == TRACKED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_real_file_bakes_upright_human_sized_and_follows_its_joints(name):
    take = bvh.read(DATA / name, min_range=None)
    joints, samples = baked_figure.bake(take)
    fig = baked_figure.heights(joints, take.skeleton)
    assert fig["upright"]
    assert 1.3 <= fig["head_to_foot_m"] <= 1.8
    assert baked_figure.limb_direction_errors(joints, samples, take).max() < 0.5


def test_position_channels_read_per_file():
    """Blender's exporter writes every joint's full local translation in its position channels; MakeHuman adds
    small deltas to the OFFSET; the others have them on the root only."""
    modes = {name: bvh.read_bvh_skeleton(DATA / name).position_mode for name in EXPECTED}
    assert modes.pop("blender_export_kinect_rig.bvh") == "absolute" and set(modes.values()) == {"none"}
    assert bvh.read_bvh_skeleton(DATA.parent / "meshes" / "makehuman" / "tpose.bvh").position_mode == "delta"


def test_left_is_left_toes_point_forward():
    """The performer faces the virtual sensor: toes nearer to it than ankles, left hand on the sensor's right."""
    k = KINECT_V1.index
    for name in ("cmu_01_01.bvh", "mixamo_freebvh.bvh", "univrm_sample.bvh", "mocapbank_sit_down.bvh"):
        p = bvh.read(DATA / name, min_range=None).positions[0]
        assert p[k("FootLeft"), 2] < p[k("AnkleLeft"), 2] and p[k("FootRight"), 2] < p[k("AnkleRight"), 2], name
        assert p[k("ShoulderLeft"), 0] < p[k("ShoulderRight"), 0], name


def test_missing_hands_and_feet_are_extrapolated_along_the_limb():
    take = bvh.read(DATA / "video2bvh_dance.bvh", min_range=None)
    k = KINECT_V1.index
    p = take.positions
    fore = p[:, k("WristLeft")] - p[:, k("ElbowLeft")]
    hand = p[:, k("HandLeft")] - p[:, k("WristLeft")]
    np.testing.assert_allclose(hand, 0.3 * fore, atol=1e-9)
    foot = p[:, k("FootRight")] - p[:, k("AnkleRight")]
    assert np.all(foot[:, 1] < 0)  # below the ankle
    shin = np.linalg.norm(p[:, k("AnkleRight")] - p[:, k("KneeRight")], axis=-1)
    assert np.allclose(np.linalg.norm(foot, axis=-1), 0.25 * shin * np.hypot(1, 0.4))


def test_info_prints_the_mapping_joint_by_joint(capsys):
    from kinect_retarget.cli import main
    assert main(["info", str(DATA / "video2bvh_dance.bvh")]) == 0
    out = capsys.readouterr().out
    fields = dict(ln.split(None, 1) for ln in out.splitlines() if len(ln.split(None, 1)) == 2)
    assert fields["unit"].startswith("millimetres (guessed from the standing height")
    assert fields["up_axis"] == "+Z" and fields["position_channels"] == "position channels on the root only"
    lines = out.splitlines()
    start = lines.index("mapping")
    assert [line.split()[0] for line in lines[start + 1:start + 21]] == list(KINECT_V1.joints)
    assert ["HandLeft", "- (no hand node: extrapolated along the forearm)"] in [ln.split(None, 1) for ln in lines]
