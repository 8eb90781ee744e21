"""Joint proposals from classified body parts: per-part mean shift (Shotton et al. 2011, section 4).

Each person cell of the tracker's grid gets part probabilities from the forest (part_forest.py). For every
limb joint, the cells likely to be its part (probability > PROB_MIN) vote with their probability times the
area the cell stands for (z squared), and mean shift with a Gaussian kernel finds the densest place; that
point, pushed behind the surface by about the limb's radius, is the proposal, and the weight gathered around
it is its confidence (square metres of likely part).
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
TORSO_FRONT = 0.06     # m: torso cells this much nearer than their median are a forearm held before the chest


@dataclass
class Proposals:
    positions: np.ndarray    # (20, 3) Kinect camera space (rows of joints without a proposal are 0)
    confidence: np.ndarray   # (20,) square metres of likely part around the proposal; 0 = no proposal
    cells: tuple             # (rows, cols) of the classified grid cells
    probs: np.ndarray        # (N, parts) their part probabilities


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
    for joint, part in JOINT_PART.items():
        p = probs[:, PART[part]]
        sel = np.flatnonzero(p > PROB_MIN)
        if len(sel) < 3:
            continue
        x, w = pts[sel], p[sel] * area[sel]
        s = x[np.argsort(-p[sel])[:SEEDS]]
        for _ in range(ITERATIONS):
            k = np.exp(-np.sum((s[:, None] - x[None]) ** 2, axis=-1) / BANDWIDTH ** 2) * w
            s = (k @ x) / np.maximum(k.sum(axis=1, keepdims=True), 1e-12)
        k = np.exp(-np.sum((s[:, None] - x[None]) ** 2, axis=-1) / BANDWIDTH ** 2) * w
        best = int(np.argmax(k.sum(axis=1)))
        j = KINECT_V1.index(joint)
        kind = next(n for n in DEPTH_INSIDE if joint.startswith(n))
        pos[j] = s[best] + s[best] / np.linalg.norm(s[best]) * DEPTH_INSIDE[kind]
        conf[j] = float(k[best].sum())
    return Proposals(pos, conf, (rows, cols), probs)


def torso_seen(props: Proposals, xyz: np.ndarray) -> np.ndarray | None:
    """Where the forest sees the torso: the median of the cells likely to be one of its quarters, leaving out
    those well before the rest (an arm folded across the chest that the forest takes for torso). `xyz`: the
    grid's camera-space points. None when too few cells are the torso's."""
    sel = props.probs[:, TORSO_PARTS].sum(axis=1) > TORSO_PROB
    if sel.sum() < TORSO_CELLS:
        return None
    rows, cols = props.cells
    pts = xyz[rows[sel], cols[sel]]
    pts = pts[pts[:, 2] > np.median(pts[:, 2]) - TORSO_FRONT]
    return np.median(pts, axis=0)
