"""Joint proposals from classified body parts: per-part mean shift (Shotton et al. 2011, section 4).

Each person cell of the tracker's grid gets part probabilities from the forest (part_forest.py). For every
limb joint, the cells likely to be its part (probability > PROB_MIN) vote with their probability times the
area the cell stands for (z squared), and mean shift with a Gaussian kernel finds the densest place; that
point, pushed behind the surface by about the limb's radius, is the proposal, and the weight gathered around
it is its confidence (square metres of likely part). Where an arm joint's left and right proposals find the same
place, the forest saw one part unsure of its side: it is the surer side's, and the other side's is looked for
away from it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.skeletons import KINECT_V1
from .body_model_fit import DEPTH_INSIDE
from .body_parts import JOINT_PART, PART
from .part_forest import BACKGROUND_DEPTH, PartForest

PROB_MIN = 0.14        # Shotton's probability threshold
BANDWIDTH = 0.065      # metres, Shotton's mean-shift bandwidth
SEEDS = 4              # starting points per part (its most likely cells)
ITERATIONS = 6
MAX_CELLS = 1500       # classify at most this many cells of a frame (every k-th beyond that)
TORSO_PARTS = [PART[f"torso_{h}_{s}"] for h in ("upper", "lower") for s in ("left", "right")]
TORSO_PROB = 0.5       # a cell is the torso's where its four quarters together are this likely
TORSO_CELLS = 30       # fewer such cells: the forest does not see the torso
SHARED_MODE = 0.05     # m: a left and a right proposal this near are one part seen (its side unsure)
SHARED_AWAY = 0.15     # m from it the other side's part is looked for
TORSO_FRONT = 0.06     # m: torso cells this much nearer than their median are a forearm held before the chest

# the arms' joints whose two sides may share a proposal (feet and knees together are often both really there:
# dropping one side's lost tracked feet and knees, 82.0 -> 79.1 % on subjects 3-4)
PAIRS = [(KINECT_V1.index(j + "Left"), KINECT_V1.index(j + "Right")) for j in ("Elbow", "Wrist", "Hand")]


@dataclass
class Proposals:
    positions: np.ndarray    # (20, 3) Kinect camera space (rows of joints without a proposal are 0)
    confidence: np.ndarray   # (20,) square metres of likely part around the proposal; 0 = no proposal
    cells: tuple             # (rows, cols) of the classified grid cells
    probs: np.ndarray        # (N, parts) their part probabilities
    points: np.ndarray       # (N, 3) their camera-space points
    areas: np.ndarray        # (N,) square metres of surface each stands for (the proposals' vote weights)


def propose(forest: PartForest, grid, mask: np.ndarray) -> Proposals:
    """Classify the person's cells of `grid` (segmentation.DepthGrid) and propose the limb joints."""
    rows, cols = np.nonzero(mask)
    if len(rows) > MAX_CELLS:
        keep = np.arange(0, len(rows), int(np.ceil(len(rows) / MAX_CELLS)))
        rows, cols = rows[keep], cols[keep]
    zb = np.where(mask, grid.z, BACKGROUND_DEPTH)
    probs = forest.classify(zb, rows, cols, grid.camera.f / grid.step)
    pts = grid.xyz[rows, cols]
    area = pts[:, 2] ** 2 * (grid.step / grid.camera.f) ** 2
    pos, conf = np.zeros((20, 3)), np.zeros(20)
    votes = {}
    for joint, part in JOINT_PART.items():
        p = probs[:, PART[part]]
        sel = np.flatnonzero(p > PROB_MIN)
        if len(sel) < 3:
            continue
        j = KINECT_V1.index(joint)
        votes[j] = (pts[sel], p[sel] * area[sel], p[sel])
        mode, conf[j] = _mean_shift(*votes[j])
        pos[j] = _behind(mode, joint)
    for left, right in PAIRS:
        if min(conf[left], conf[right]) > 0 and np.linalg.norm(pos[left] - pos[right]) < SHARED_MODE:
            # both sides found the same place: the forest saw one part and was unsure of its side. It is
            # the surer side's; the other side's part is looked for away from it (a hanging hand whose
            # few cells lost the vote to the raised hand's), else it has no proposal
            weaker = left if conf[left] < conf[right] else right
            x, w, pr = votes[weaker]
            away = np.linalg.norm(x - pos[weaker], axis=1) > SHARED_AWAY
            pos[weaker], conf[weaker] = 0.0, 0.0
            if away.sum() >= 3:
                mode, conf[weaker] = _mean_shift(x[away], w[away], pr[away])
                pos[weaker] = _behind(mode, KINECT_V1.joints[weaker])
    return Proposals(pos, conf, (rows, cols), probs, pts, area)


def _mean_shift(x: np.ndarray, w: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, float]:
    """The densest place of points `x` weighted `w`, from the SEEDS likeliest (`p`), and the weight around it."""
    s = x[np.argsort(-p)[:SEEDS]]
    for _ in range(ITERATIONS):
        k = np.exp(-np.sum((s[:, None] - x[None]) ** 2, axis=-1) / BANDWIDTH ** 2) * w
        s = (k @ x) / np.maximum(k.sum(axis=1, keepdims=True), 1e-12)
    k = np.exp(-np.sum((s[:, None] - x[None]) ** 2, axis=-1) / BANDWIDTH ** 2) * w
    best = int(np.argmax(k.sum(axis=1)))
    return s[best], float(k[best].sum())


def _behind(surface: np.ndarray, joint: str) -> np.ndarray:
    """A joint's place behind the surface point where its part is densest, by about the limb's radius."""
    kind = next(n for n in DEPTH_INSIDE if joint.startswith(n))
    return surface + surface / np.linalg.norm(surface) * DEPTH_INSIDE[kind]


def torso_seen(props: Proposals) -> np.ndarray | None:
    """Where the forest sees the torso: the median of the cells likely to be one of its quarters, leaving out
    those well before the rest (an arm folded across the chest that the forest takes for torso). None when
    too few cells are the torso's."""
    sel = props.probs[:, TORSO_PARTS].sum(axis=1) > TORSO_PROB
    if sel.sum() < TORSO_CELLS:
        return None
    pts = props.points[sel]
    pts = pts[pts[:, 2] > np.median(pts[:, 2]) - TORSO_FRONT]
    return np.median(pts, axis=0)
