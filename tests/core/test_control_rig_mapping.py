"""Structure mapping of generated control rigs (issue 16), in numpy: the Rigify rig Blender generates (706
bones, tests/data/rigs/rigify_generated.json) with random names and in random order maps exactly as the
'rigify' preset; without its links (deform, shapes, constraints) it is refused, never mapped wrongly; plain
rigs never take the control-rig route; the finger controls and the root are found too."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.armature_mapping import structure_mapping_for
from kinect_retarget.core.control_rig_fingers import finger_chains_by_structure
from kinect_retarget.core.control_rig_mapping import Constraint, RigLinks, deform_parents, is_control_rig, map_armature
from kinect_retarget.core.hand_pose import finger_chains
from kinect_retarget.core.presets import PRESETS, build_mapping
from kinect_retarget.core.root_motion import followed_root
from kinect_retarget.core.structure_mapping import StructureError
from tests.rigs.control_rigs import reordered, rigify_controls
from tests.rigs.humanoid_rigs import build, renamed
from tests.rigs.layouts import LAYOUTS


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_generated_rigify_rig_renamed_and_reordered_maps_exactly_as_its_preset(seed):
    rig, links = rigify_controls()
    rig, links = reordered(rig, links, seed)
    anon, back = renamed(rig, seed)
    assert is_control_rig(anon.parents, links)
    found = map_armature(anon.names, anon.parents, anon.heads, anon.tails, links)
    assert {back[b]: j for b, j in found.mapping.items()} == PRESETS["rigify"]
    torso = next(b for b, o in back.items() if o == "torso")
    assert found.joints["HipCenter"].startswith(torso)
    # through the presets' entry point, as `auto` does when no preset knows the names
    target = anon.target()
    target.links = links
    used, mapping = build_mapping("auto", anon.names, None, target)
    assert used == "structure" and {back[b]: j for b, j in mapping.items()} == PRESETS["rigify"]


def test_deform_tree_of_the_generated_rig_is_the_metarig_body():
    """DEF bones hang from ORG and root bones; linked through ORG twins they form one body tree."""
    rig, links = rigify_controls()
    size = float(np.linalg.norm(np.ptp(np.concatenate([rig.heads, rig.tails]), axis=0)))
    tree = deform_parents(rig.parents, rig.heads, rig.tails, links, 1e-3 * size)
    name = {b: rig.names[b] for b in tree}
    parent_of = {name[b]: (rig.names[p] if p >= 0 else None) for b, p in tree.items()}
    assert [n for n, p in parent_of.items() if p is None] == ["DEF-spine"]
    assert rig.names[rig.parents[rig.names.index("DEF-thigh.L")]] == "ORG-spine"   # not a deform parent
    assert parent_of["DEF-thigh.L"] == "DEF-spine" and parent_of["DEF-upper_arm.L"] == "DEF-shoulder.L"
    assert parent_of["DEF-shoulder.R"] == "DEF-spine.003" and parent_of["DEF-hand.L"] == "DEF-forearm.L.001"


def test_without_its_links_the_control_rig_is_refused_not_mapped_wrongly():
    rig, _ = rigify_controls()
    anon, _ = renamed(rig, 5)
    with pytest.raises(StructureError, match="no pelvis|no chest"):
        structure_mapping_for(anon.names, anon.parents, anon.heads, anon.tails)
    with pytest.raises(StructureError):
        map_armature(anon.names, anon.parents, anon.heads, anon.tails, None)


def test_a_control_missing_leaves_its_joint_unmapped_with_a_note():
    """Take the custom shape off the FK forearm: no other control spans the forearm (the IK one is a
    mechanism bone), so WristLeft stays unmapped and a note says which deform bone had no control."""
    rig, links = rigify_controls()
    shaped = links.shaped.copy()
    shaped[rig.names.index("forearm_fk.L")] = False
    found = map_armature(rig.names, rig.parents, rig.heads, rig.tails, RigLinks(links.deform, shaped,
                                                                                 links.constraints))
    assert "WristLeft" not in found.mapping.values() and "forearm_fk.R" in found.mapping
    assert any(n.startswith("WristLeft: no control") for n in found.notes)


@pytest.mark.parametrize("family", sorted(LAYOUTS))
def test_plain_rigs_do_not_take_the_control_rig_route(family):
    """A rig whose bones all deform (no shapes, no constraints) maps as before; so does one whose few
    constrained helpers are the minority."""
    rig = build(LAYOUTS[family])
    n = len(rig.names)
    plain = RigLinks(np.ones(n, bool), np.zeros(n, bool), tuple(() for _ in range(n)))
    assert not is_control_rig(rig.parents, plain)
    helpers = RigLinks(np.ones(n, bool), np.eye(1, n, 0, dtype=bool)[0],
                       tuple((Constraint("DAMPED_TRACK", (0,)),) if b % 5 == 0 else () for b in range(n)))
    assert not is_control_rig(rig.parents, helpers)
    expect = structure_mapping_for(rig.names, rig.parents, rig.heads, rig.tails).mapping
    assert map_armature(rig.names, rig.parents, rig.heads, rig.tails, plain).mapping == expect


def test_root_motion_bone_of_the_renamed_rig_is_the_root_its_torso_follows():
    """Rigify's torso hangs from a parentless bone whose Armature constraint reads `root`: that is the bone
    root motion goes onto (the preset names it; renamed, it is found through the constraint)."""
    rig, links = rigify_controls()
    anon, back = renamed(rig, 4)
    target = anon.target()
    target.links = links
    torso = next(b for b, o in back.items() if o == "torso")
    assert back[followed_root(target, torso)] == "root"
    assert followed_root(anon.target(), torso) is None   # without links: nothing to follow


@pytest.mark.parametrize("seed", [1, 2])
def test_finger_controls_of_the_renamed_rig_are_the_ones_rigify_names(seed):
    """Kinect v2's hand poses drive Rigify's finger controls, found by name (hand_pose.FINGER_NAMES); on the
    renamed, reordered rig the same controls are found by structure, finger by finger."""
    rig, links = rigify_controls()
    rig, links = reordered(rig, links, seed)
    anon, back = renamed(rig, seed)
    for side, tag in (("Left", ".L"), ("Right", ".R")):
        hand = next(i for i, b in enumerate(anon.names) if back[b] == "hand_fk" + tag)
        found = finger_chains_by_structure(anon.parents, anon.heads, anon.tails, links, hand)
        assert {f: [back[anon.names[b]] for b in chain] for f, chain in found.items()} == \
            finger_chains(rig.names, side)
    plain = build(LAYOUTS["ue5-mannequin"])   # other rigs: by name only
    assert finger_chains_by_structure(plain.parents, plain.heads, plain.tails, None, 0) is None
