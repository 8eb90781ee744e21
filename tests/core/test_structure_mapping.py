"""The structural mapper on its own: armature-style input (rest pose only, any node order, twist bones),
Kinect v2 names one to one, names only as a tiebreak, clear refusals."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V2
from kinect_retarget.core.structure_mapping import ROLES, StructureError, map_structure
from kinect_retarget.core.structure_names import name_side
from kinect_retarget.takes import load_take
from kinect_retarget.takes.bvh import read_bvh_skeleton

REPO = Path(__file__).resolve().parents[2]


def _t_pose(toes=True, names=None):
    """A Z-up T-pose (metres, facing -Y) as an armature would give it: bone heads plus leaf tails, with twist
    bones in the arms and legs, nodes deliberately out of order."""
    nodes = [("pelvis", None, (0, 0, 1.0)), ("spine1", "pelvis", (0, 0, 1.15)), ("spine2", "spine1", (0, 0, 1.3)),
             ("chest", "spine2", (0, 0, 1.45)), ("neck", "chest", (0, 0, 1.52)), ("head", "neck", (0, 0, 1.62)),
             ("head_top", "head", (0, 0, 1.78))]
    for s, x in (("L", 1), ("R", -1)):
        nodes += [(f"clavicle.{s}", "chest", (0.03 * x, 0, 1.43)), (f"upper_arm.{s}", f"clavicle.{s}", (0.18 * x, 0, 1.43)),
                  (f"upper_arm_twist.{s}", f"upper_arm.{s}", (0.32 * x, 0, 1.43)),
                  (f"forearm.{s}", f"upper_arm_twist.{s}", (0.46 * x, 0, 1.43)),
                  (f"forearm_twist.{s}", f"forearm.{s}", (0.58 * x, 0, 1.43)),
                  (f"hand.{s}", f"forearm_twist.{s}", (0.70 * x, 0, 1.43)),
                  (f"finger.{s}", f"hand.{s}", (0.80 * x, 0, 1.43)), (f"finger_tip.{s}", f"finger.{s}", (0.88 * x, 0, 1.43)),
                  (f"thumb.{s}", f"hand.{s}", (0.74 * x, -0.04, 1.43)),
                  (f"thigh.{s}", "pelvis", (0.1 * x, 0, 0.95)), (f"shin.{s}", f"thigh.{s}", (0.1 * x, 0, 0.52)),
                  (f"foot.{s}", f"shin.{s}", (0.1 * x, 0, 0.08))]
        if toes:
            nodes += [(f"toe.{s}", f"foot.{s}", (0.1 * x, -0.12, 0.02)), (f"toe_tip.{s}", f"toe.{s}", (0.1 * x, -0.18, 0.02))]
    order = np.random.default_rng(3).permutation(len(nodes))  # parents need not come first
    nodes = [nodes[i] for i in order]
    labels = [n for n, _, _ in nodes]
    parents = [labels.index(p) if p else -1 for _, p, _ in nodes]
    rest = np.array([xyz for _, _, xyz in nodes], dtype=float)
    ends = [n.endswith(("_tip", "_top")) for n in labels]
    return (names or labels), labels, parents, rest, ends


def test_armature_style_rest_pose_maps_past_twist_and_finger_bones():
    names, labels, parents, rest, ends = _t_pose()
    m = map_structure(names, parents, rest, end_site=ends)
    got = {r: tuple(labels[i] for i in m.roles[r].average) for r in ROLES}
    assert got["HipCenter"] == ("pelvis",) and got["Spine"] == ("spine2", "chest")
    assert got["ShoulderLeft"] == ("upper_arm.L",) and got["ElbowLeft"] == ("forearm.L",)
    assert got["WristLeft"] == ("hand.L",) and got["HandLeft"] == ("finger.L",)
    assert got["HipRight"] == ("thigh.R",) and got["KneeRight"] == ("shin.R",) and got["AnkleRight"] == ("foot.R",)
    assert got["FootRight"] == ("toe.R",) and got["Head"] == ("head", "head_top")
    assert (m.up_axis, m.up_sign) == (2, 1.0)
    np.testing.assert_allclose(m.forward, [0, -1, 0], atol=1e-9)  # the toes point along -Y


def test_left_and_right_come_from_the_figure_not_the_names():
    """Names swapped on purpose: the toes say which way the figure faces, so the structure wins."""
    _, labels, parents, rest, ends = _t_pose()
    swapped = [n.replace(".L", ".X").replace(".R", ".L").replace(".X", ".R") for n in labels]
    m = map_structure(swapped, parents, rest, end_site=ends)
    assert labels[m.roles["ShoulderLeft"].node] == "upper_arm.L"  # at +X, the left of a figure facing -Y


def test_names_break_the_tie_when_the_figure_cannot_tell():
    names, labels, parents, rest, ends = _t_pose(toes=False)  # no toes, straight legs, one frame
    m = map_structure(names, parents, rest, end_site=ends)
    assert labels[m.roles["HipLeft"].node] == "thigh.L"
    assert any("joint names" in n for n in m.notes)
    assert [name_side(n) for n in ("LeftArm", "thigh.R", "l_hip", "lShldr", "LHipJoint", "Spine", "RightUpLeg")] \
        == [1, -1, 1, 1, 1, 0, -1]


def test_kinect_v2_names_map_one_to_one():
    take = load_take(REPO / "sample_takes" / "kinect_v2_ges01_wavehand.krtake")
    frames = take.positions[take.states.min(axis=1) > 0][:60]
    m = map_structure(KINECT_V2.joints, KINECT_V2.parents, frames[0], frames)
    v1_from_v2 = {"HipCenter": "SpineBase", "Spine": "SpineMid", "ShoulderCenter": "SpineShoulder"}
    for role in ROLES:
        match = m.roles[role]
        assert KINECT_V2.joints[match.node] == v1_from_v2.get(role, role) and match.how == "Kinect name"
    assert (m.up_axis, m.up_sign) == (1, 1.0)


def test_same_answer_with_and_without_motion_for_a_bvh():
    motion = read_bvh_skeleton(REPO / "tests" / "data" / "bvh" / "cmu_01_01.bvh")
    sk = motion.skeleton
    with_motion = map_structure(sk.names, sk.parents, motion.rest_positions, motion.positions, sk.is_end_site)
    rest_only = map_structure(sk.names, sk.parents, motion.rest_positions, end_site=sk.is_end_site)
    assert with_motion.indices() == rest_only.indices()


def test_refusals_name_what_is_missing():
    names, labels, parents, rest, _ = _t_pose()
    leg_r = ("thigh", "shin", "foot", "toe")
    one_leg = [i for i, n in enumerate(labels) if not (n.endswith(".R") and n.startswith(leg_r))]
    keep = {old: new for new, old in enumerate(one_leg)}
    with pytest.raises(StructureError, match="no node where a spine and two legs meet"):
        map_structure([labels[i] for i in one_leg], [keep.get(parents[i], -1) for i in one_leg], rest[one_leg])
    with pytest.raises(StructureError, match="skeleton arrays disagree"):
        map_structure(names, parents[:-1], rest)
    with pytest.raises(StructureError, match="frames must be finite"):
        map_structure(names, parents, rest, np.full((2,) + rest.shape, np.nan))
