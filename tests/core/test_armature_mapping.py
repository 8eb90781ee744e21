"""Any humanoid armature mapped by structure alone (issue 16): every rig the tests build, with every bone name
replaced by a seeded random string, maps exactly as its preset does; also with twist bones beside or inside
the limbs, fingers or none, face bones, an A-pose and a T-pose; then a take baked onto each follows the
performer."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.armature_mapping import structure_mapping_for, twist_leaves
from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.kinect_rig_layout import generated_rig, typical_segment_lengths
from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings
from kinect_retarget.core.presets import PRESETS, build_mapping, detect_preset
from kinect_retarget.core.quat import normalize
from kinect_retarget.core.retarget import resolve_mapping
from kinect_retarget.core.skeletons import KINECT_V1, KINECT_V2
from kinect_retarget.core.structure_mapping import StructureError
from kinect_retarget.core.target_rig import evaluate_pose
from kinect_retarget.takes import load_take
from tests.rigs.humanoid_rigs import Rig, build, from_target, makehuman_rig, renamed
from tests.rigs.layouts import LAYOUTS

VARIANTS = {"t-pose": {}, "t-pose+face": {"face": True}, "a-pose+face": {"a_pose_deg": 40, "face": True},
            "no-fingers": {"fingers": False},
            "a-pose-30-no-fingers": {"a_pose_deg": 30, "fingers": False}}


def _by_structure(rig: Rig, seed: int = 11) -> dict[str, str]:
    """Structure mapping of the rig with its names randomised, translated back to the original names."""
    anon, back = renamed(rig, seed)
    assert not set(anon.names) & set(rig.names)
    found = structure_mapping_for(anon.names, anon.parents, anon.heads, anon.tails).mapping
    return {back[b]: j for b, j in found.items()}


def _preset(rig: Rig, preset: str) -> dict[str, str]:
    return {b: j for b, j in PRESETS[preset].items() if b in rig.names}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
@pytest.mark.parametrize("family", sorted(LAYOUTS))
def test_preset_families_renamed_map_exactly_as_their_preset(family, variant):
    rig = build(LAYOUTS[family], **VARIANTS[variant])
    assert detect_preset(rig.names) == family  # the names alone find the family's preset
    assert _by_structure(rig) == _preset(rig, family)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_makehuman_skeleton_renamed_maps_as_its_preset(seed):
    rig = makehuman_rig()
    assert _by_structure(rig, seed) == _preset(rig, "makehuman")
    assert _preset(rig, "makehuman") == _preset(rig, "mpfb-default")


@pytest.mark.parametrize("skeleton", [KINECT_V1, KINECT_V2], ids=lambda s: s.name)
def test_generated_kinect_rig_renamed_maps_as_its_preset(skeleton):
    """The generated rig (a straight T-pose: no bend tells the joints, proportions do). Kinect v2's hand tips
    and thumbs are fingers, left unmapped by structure; every other bone drives the same segment."""
    target = generated_rig(skeleton, typical_segment_lengths(skeleton))
    rig = from_target(target)
    got = resolve_mapping(skeleton, target, _by_structure(rig))
    want = resolve_mapping(skeleton, target, {b: j for b, j in _preset(rig, "kinect").items()
                                              if not j.startswith(("HandTip", "Thumb"))})
    assert {(m.bone, m.head, m.tail) for m in got} == {(m.bone, m.head, m.tail) for m in want}


def test_twist_leaves_are_found_beside_limbs_only():
    rig = build(LAYOUTS["ue5-mannequin"])
    found = {rig.names[b] for b in twist_leaves(rig.parents, rig.heads, rig.tails)}
    assert found == {n for n in rig.names if "twist" in n}
    bare = build(LAYOUTS["vroid"], fingers=False)  # a hand without fingers is a leaf, and no twist bone
    assert not twist_leaves(bare.parents, bare.heads, bare.tails)


def test_auto_falls_back_to_structure_and_refuses_a_chair():
    rig = build(LAYOUTS["daz-genesis8"])
    anon, back = renamed(rig, 5)
    used, mapping = build_mapping("auto", anon.names, {anon.names[0]: ""}, anon.target())
    assert used == "structure" and anon.names[0] not in mapping
    assert {back[b]: j for b, j in mapping.items()} == {b: j for b, j in _preset(rig, "daz-genesis8").items()
                                                         if b != rig.names[0]}
    chair = Rig(["Leg", "Seat", "Back"], np.array([-1, 0, 1]), np.array([[0, 0, 0], [0, 0, 0.5], [0, 0.2, 0.5]]),
                np.array([[0, 0, 0.5], [0, 0.2, 0.5], [0, 0.2, 1.0]]))
    with pytest.raises(ValueError, match="no bone-mapping preset.*by structure"):
        build_mapping("auto", chair.names, None, chair.target())
    with pytest.raises(StructureError):
        structure_mapping_for(chair.names, chair.parents, chair.heads, chair.tails)


@pytest.fixture(scope="module")
def hop():
    from kinect_retarget.assets import motion_clip
    return load_take(motion_clip("131_03")).slice(slice(0, 240, 2))


@pytest.mark.parametrize("family", sorted(LAYOUTS) + ["makehuman"])
def test_take_baked_by_structure_follows_the_performer(family, hop):
    """Each family's rig, names randomised and mapped by structure: every mapped limb bone points along the
    performer's segment (the solver's own check, without Blender)."""
    rig = makehuman_rig() if family == "makehuman" else build(LAYOUTS[family], a_pose_deg=35, face=True)
    anon, _ = renamed(rig, 3)
    target = anon.target()
    used, mapping = build_mapping("auto", anon.names, None, target)
    assert used == "structure"
    pipe = RetargetPipeline(hop.skeleton, target, mapping, RetargetSettings(filter="none"))
    motion = pipe.process_take(hop)
    posed = evaluate_pose(target, pipe.retargeter.bone_indices, motion.quats)
    p = kinect_to_blender(hop.positions[motion.samples])
    for m in pipe.retargeter.mapped:
        if m.is_root or m.tail_name.startswith(("ShoulderCenter", "Head", "Spine", "Neck")):
            continue  # axial bones follow their segment too, but a spine split into several bones only in part
        src = normalize(p[:, m.tail] - p[:, m.head])
        err = np.degrees(np.arccos(np.clip(np.sum(src * posed[:, m.index, :3, 1], -1), -1, 1)))
        assert err.max() < 1e-3, (family, m.bone, m.tail_name)


def _hanim_rig(vc4: bool = False) -> Rig:
    """A small H-Anim humanoid (bones named after the joint at their head), with the standard's hierarchy
    (ISO/IEC 19774, LOA 2+, intermediate vertebrae left out as the standard allows): vl5 -> vt1 -> skullbase, and
    the sternoclavicular joints hang from vt1 (the test armature in tests/blender/test_lift_clip.py likewise).
    With vc4 the neck is two short bones, vt1 -> vc4 -> skullbase, each about 6 cm."""
    from tests.rigs.humanoid_rigs import ANKLE, BALL, CLAV, ELBOW, HIP, HIPS, KNEE, KNUCKLE, NECK_BASE, \
        SHOULDER, SKULL, TOP, WRIST
    bones = [("sacroiliac", None, HIPS, (0, 0, 1.2)), ("vl5", "sacroiliac", (0, 0, 1.2), NECK_BASE),
             ("vt1", "vl5", NECK_BASE, SKULL), ("skullbase", "vt1", SKULL, TOP)]
    if vc4:
        mid = tuple((np.array(NECK_BASE) + np.array(SKULL)) / 2)
        bones[2:] = [("vt1", "vl5", NECK_BASE, mid), ("vc4", "vt1", mid, SKULL), ("skullbase", "vc4", SKULL, TOP)]
    for s, x in (("l_", 1.0), ("r_", -1.0)):
        m = lambda p: (p[0] * x, p[1], p[2])  # noqa: E731
        bones += [(f"{s}sternoclavicular", "vt1", m(CLAV), m(SHOULDER)),
                  (f"{s}shoulder", f"{s}sternoclavicular", m(SHOULDER), m(ELBOW)),
                  (f"{s}elbow", f"{s}shoulder", m(ELBOW), m(WRIST)), (f"{s}wrist", f"{s}elbow", m(WRIST), m(KNUCKLE)),
                  (f"{s}hip", "sacroiliac", m(HIP), m(KNEE)), (f"{s}knee", f"{s}hip", m(KNEE), m(ANKLE)),
                  (f"{s}ankle", f"{s}knee", m(ANKLE), m(BALL))]
    names = [b[0] for b in bones]
    parents = np.array([names.index(b[1]) if b[1] else -1 for b in bones])
    return Rig(names, parents, np.array([b[2] for b in bones], float), np.array([b[3] for b in bones], float))


@pytest.mark.parametrize("vc4", [False, True], ids=["neck-vt1", "neck-vt1-vc4"])
@pytest.mark.parametrize("seed", [1, 2])
def test_hanim_armature_renamed_maps_as_its_preset(seed, vc4):
    rig = _hanim_rig(vc4)
    assert detect_preset(rig.names) == "hanim"
    assert _by_structure(rig, seed) == _preset(rig, "hanim")
