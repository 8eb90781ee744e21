"""A part the forest sees once but is unsure of the side of: both sides' proposals find the same place. On real
depth (pick up and throw) the raised right hand's cells were also likely left hand, more than the left hand's
own few cells by the hip, so the left hand was proposed on the right one and the left arm raised to it for 16
frames. The place is the surer side's; the other side's part is looked for away from it."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth import part_proposals
from kinect_retarget.depth.body_parts import PART, PARTS
from kinect_retarget.depth.part_proposals import propose

LEFT, RIGHT = KINECT_V1.index("HandLeft"), KINECT_V1.index("HandRight")
RAISED, HANGING = np.array([0.05, 0.5, 2.3]), np.array([-0.3, -0.35, 2.7])


class _Forest:
    def __init__(self, probs):
        self.probs = probs

    def classify(self, zb, rows, cols, cells_per_m):
        return self.probs


def _proposals(hanging_cells: int):
    rng = np.random.default_rng(5)
    raised = RAISED + rng.normal(0.0, 0.02, (30, 3))
    hanging = HANGING + rng.normal(0.0, 0.02, (hanging_cells, 3))
    pts = np.concatenate([raised, hanging])
    probs = np.zeros((len(pts), len(PARTS)))
    probs[:30, PART["hand_right"]] = 0.55
    probs[:30, PART["hand_left"]] = 0.4    # the raised hand is also likely left, more than the left's own cells
    probs[30:, PART["hand_left"]] = 0.35
    xyz = pts.reshape(1, -1, 3)
    mask = np.ones(xyz.shape[:2], bool)
    grid = SimpleNamespace(xyz=xyz, z=xyz[..., 2], step=4, camera=SimpleNamespace(f=571.26))
    return propose(_Forest(probs), grid, mask)


def test_the_less_sure_side_looks_for_its_part_away_from_a_shared_place(monkeypatch):
    props = _proposals(hanging_cells=8)
    assert np.linalg.norm(props.positions[RIGHT] - RAISED) < 0.06
    assert np.linalg.norm(props.positions[LEFT] - HANGING) < 0.06
    assert 0 < props.confidence[LEFT] < props.confidence[RIGHT]
    monkeypatch.setattr(part_proposals, "SHARED_MODE", 0.0)   # as before: both hands on the raised one
    props = _proposals(hanging_cells=8)
    assert np.linalg.norm(props.positions[LEFT] - RAISED) < 0.06


def test_a_side_with_nothing_away_from_the_shared_place_has_no_proposal():
    props = _proposals(hanging_cells=0)
    assert np.linalg.norm(props.positions[RIGHT] - RAISED) < 0.06
    assert props.confidence[LEFT] == 0.0
