"""The paper's joint rule (joints_paper.py): joints from the level-set centroids, so K and eq. 6's
normalization change them; measured against MakeHuman's reference skeleton beside the default rule."""
import numpy as np
import pytest

from kinect_retarget.autorig import autorig
from kinect_retarget.autorig.inside import inside_mesh
from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.sim.autorig_scoring import joint_errors, reference_joints, symmetry_error


@pytest.fixture(scope="module")
def paper_rigs(mh):
    return {k: autorig(mh.body, levels=k, joints="paper") for k in (2, 4, 7)}


def test_levels_move_the_paper_joints_and_weights(mh, paper_rigs):
    for a, b in ((2, 4), (4, 7)):
        moved = np.linalg.norm(paper_rigs[a].joints - paper_rigs[b].joints, axis=1).max() / mh.height * 100
        assert moved > 0.5, (a, b, moved)
        assert not np.array_equal(paper_rigs[a].weight_index, paper_rigs[b].weight_index)
    assert paper_rigs[4].report["joint_rule"] == "paper"


def test_global_normalization_fewer_points_other_joints(mh, paper_rigs):
    rig = autorig(mh.body, levels=4, joints="paper", normalization="global")
    assert len(rig.paper.points) < len(paper_rigs[4].paper.points)  # the arms span fewer levels
    assert np.abs(rig.joints - paper_rigs[4].joints).max() > 1e-3 * mh.height


def test_paper_rule_accuracy_symmetry_inside(mh, paper_rigs):
    rig = paper_rigs[4]
    err = joint_errors(rig.joints, reference_joints(mh), mh.height)
    assert err.mean() < 2.5 and err.max() < 5.5, dict(zip(KINECT_V1.joints, err.round(2)))
    assert symmetry_error(rig.joints, np.array([1.0, 0, 0]), np.zeros(3), mh.height) < 0.5
    # the chain cuts across bends: at K = 4 the neck, wrists and feet fall outside (15 of 20 inside); the
    # default rule has all 20 inside (test_autorig_makehuman.py)
    assert inside_mesh(rig.joints, mh.body.vertices, mh.body.faces).sum() >= 15


def test_default_rule_is_the_better_one(mh, paper_rigs):
    default = autorig(mh.body)
    ref = reference_joints(mh)
    assert default.report["joint_rule"] == "fractions"
    paper_error = joint_errors(paper_rigs[4].joints, ref, mh.height).mean()
    assert joint_errors(default.joints, ref, mh.height).mean() < paper_error


def test_bad_choices_are_refused(mh):
    with pytest.raises(ValueError, match="joints"):
        autorig(mh.body, joints="nearest")
    with pytest.raises(ValueError, match="normalization"):
        autorig(mh.body, normalization="per-vertex")
