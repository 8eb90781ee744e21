"""Per-cell body-part classification by a randomized decision forest over depth-difference features.

Shotton et al. (CVPR 2011): f(x) = d(x + u / d(x)) - d(x + v / d(x)), offsets u, v in metres at the pixel's
depth so the feature does not change with distance. Here d is the tracker's depth grid (every 4th pixel of
640x480), with every cell that is not the person read as BACKGROUND_DEPTH. The forest is trained offline
(tools/train_body_parts.py, on rendered MakeHuman bodies only) and shipped as one .npz of flat arrays;
inference walks all trees for all cells at once in numpy, one tree level per step.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

from ..assets import ASSETS_DIR

BACKGROUND_DEPTH = 10.0   # metres read at a probe off the person or off the image
# shipped with the package's runtime assets (kinect_retarget/assets, credits and recipe in its CREDITS.md)
MODEL_PATH = os.fspath(ASSETS_DIR / "body_parts_forest.npz")


def framed_grid(zb: np.ndarray) -> np.ndarray:
    """`zb` with one BACKGROUND_DEPTH cell all round, flattened: a probe off the grid then needs a clip, not a
    bounds test and a select."""
    framed = np.full((zb.shape[0] + 2, zb.shape[1] + 2), BACKGROUND_DEPTH)
    framed[1:-1, 1:-1] = zb
    return framed.ravel()


def _depth_differences(framed: np.ndarray, shape, rows1, cols1, offsets: np.ndarray, scale) -> np.ndarray:
    """d(x + u) - d(x + v) read from `framed_grid` (rows1, cols1: the cells' place in it, one more than in the
    grid; offsets (..., 2, 2) in metres, scale: cells per metre at each cell's depth)."""
    h, w = shape
    probe = []
    for k in (0, 1):
        r = rows1 + np.rint(offsets[..., k, 1] * scale).astype(np.int64)
        c = cols1 + np.rint(offsets[..., k, 0] * scale).astype(np.int64)
        np.clip(r, 0, h + 1, out=r)
        np.clip(c, 0, w + 1, out=c)
        r *= w + 2
        r += c
        probe.append(framed[r])
    return probe[0] - probe[1]


def probe_features(zb: np.ndarray, rows: np.ndarray, cols: np.ndarray, offsets: np.ndarray, cells_per_m: float):
    """(N,) or (N, K) feature values at cells (rows, cols) of the person depth grid `zb` (metres,
    BACKGROUND_DEPTH off the person): offsets (..., 2, 2) = (probe u, probe v) x (right, down) in metres;
    `cells_per_m` = focal length / grid step (a metre at 1 m spans that many cells)."""
    scale = cells_per_m / zb[rows, cols]
    rows1, cols1 = rows + 1, cols + 1
    if offsets.ndim == 4:   # a pool of features for every cell: broadcast (N, 1) against (K,)
        scale, rows1, cols1 = scale[:, None], rows1[:, None], cols1[:, None]
    return _depth_differences(framed_grid(zb), zb.shape, rows1, cols1, offsets, scale)


@dataclass(frozen=True)
class PartForest:
    offsets: np.ndarray     # (K, 2, 2) feature pool, metres
    feature: np.ndarray     # (nodes,) index into offsets; leaves point at themselves (left = right = node)
    threshold: np.ndarray   # (nodes,) go left when the feature <= threshold
    left: np.ndarray        # (nodes,)
    right: np.ndarray       # (nodes,)
    leaf_probs: np.ndarray  # (nodes, parts) uint8, probability x 255 (zero rows for split nodes)
    roots: np.ndarray       # (trees,) node index of each tree's root
    depth: int              # deepest leaf

    @cached_property
    def node_offsets(self) -> np.ndarray:
        """(nodes, 2, 2) each node's feature offsets (one gather a level instead of two)."""
        return self.offsets[self.feature]

    def classify(self, zb: np.ndarray, rows: np.ndarray, cols: np.ndarray, cells_per_m: float) -> np.ndarray:
        """(N, parts) float32 part probabilities of the cells (rows, cols), averaged over the trees."""
        t = len(self.roots)
        framed = framed_grid(zb)
        node = np.tile(self.roots, len(rows))   # (N * trees,): each cell's trees side by side
        rr, cc = np.repeat(rows, t) + 1, np.repeat(cols, t) + 1
        scale = cells_per_m / zb[rr - 1, cc - 1]
        for _ in range(self.depth):
            f = _depth_differences(framed, zb.shape, rr, cc, self.node_offsets[node], scale)
            node = np.where(f <= self.threshold[node], self.left[node], self.right[node])
        probs = self.leaf_probs[node].reshape(len(rows), t, -1).astype(np.float32)
        return probs.mean(axis=1) * (1.0 / 255.0)

    def save(self, path: str, **recipe) -> None:
        np.savez_compressed(path, offsets=self.offsets.astype(np.float32), feature=self.feature.astype(np.int16),
                            threshold=self.threshold.astype(np.float32), left=self.left.astype(np.int32),
                            right=self.right.astype(np.int32), leaf_probs=self.leaf_probs.astype(np.uint8),
                            roots=self.roots.astype(np.int32), depth=np.int32(self.depth),
                            recipe=np.array(repr(recipe)))


@lru_cache(maxsize=2)
def load_forest(path: str = MODEL_PATH) -> PartForest | None:
    """The shipped forest, or None when the file is missing or unreadable (the tracker then works without
    body parts)."""
    try:
        with np.load(path, allow_pickle=False) as d:
            return PartForest(d["offsets"].astype(np.float64), d["feature"].astype(np.int64),
                              d["threshold"].astype(np.float64), d["left"].astype(np.int64),
                              d["right"].astype(np.int64), d["leaf_probs"], d["roots"].astype(np.int64),
                              int(d["depth"]))
    except (OSError, KeyError, ValueError):
        return None
