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
MAX_MARGIN = 200          # cells of background round the grid for the probes (0.6 m at 0.43 m on 4-pixel cells)
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
    def node_records(self) -> np.ndarray:
        """(nodes, 8) int32, one 32-byte record a node: probe u (down, right) and probe v (down, right) in metres
        and the threshold as float32 bits, then the right and the left child. A tree level then reads its nodes
        with one gather (the node arrays are far bigger than the cache, so separate arrays cost a miss each).
        Exact for forests read from a file, which keeps offsets and thresholds in float32."""
        records = np.zeros((len(self.feature), 8), np.int32)
        o = self.offsets[self.feature]
        records[:, :5].view(np.float32)[:] = np.column_stack(
            [o[:, 0, 1], o[:, 0, 0], o[:, 1, 1], o[:, 1, 0], self.threshold])
        records[:, 5], records[:, 6] = self.right, self.left
        return records

    @cached_property
    def reach(self) -> float:
        """The farthest any probe lies from its cell, metres at 1 m."""
        return float(np.abs(self.offsets).max())

    def classify(self, zb: np.ndarray, rows: np.ndarray, cols: np.ndarray, cells_per_m: float) -> np.ndarray:
        """(N, parts) float32 part probabilities of the cells (rows, cols), averaged over the trees."""
        t = len(self.roots)
        h, w = zb.shape
        scale = cells_per_m / zb[rows, cols]
        # the grid in a margin of background as wide as the farthest probe, so no probe needs a bounds test
        # (capped for cells implausibly near the sensor, whose probes are then clipped into the margin)
        top = float(scale.max()) if len(rows) else 0.0
        need = int(np.ceil(self.reach * top)) + 1 if np.isfinite(top) else MAX_MARGIN + 1   # no depth: clip
        pad = min(need, MAX_MARGIN)
        framed = np.full((h + 2 * pad, w + 2 * pad), BACKGROUND_DEPTH)
        framed[pad:pad + h, pad:pad + w] = zb
        framed = framed.ravel()
        stride = w + 2 * pad
        at = np.repeat((rows + pad) * stride + cols + pad, t)   # each cell's trees side by side
        scale = np.repeat(scale, t)
        node = np.tile(self.roots, len(rows)).astype(np.int32)
        records = self.node_records
        for _ in range(self.depth):
            nodes = np.take(records, node, axis=0).T.copy()   # (8, N * trees), each field contiguous
            fields = nodes[:5].view(np.float32).astype(np.float64)
            probe = np.rint(fields[:4] * scale).astype(np.int64)
            if need > pad:
                np.clip(probe, -pad, pad, out=probe)
            probe[0::2] *= stride
            probed = framed[probe[0::2] + probe[1::2] + at]   # d(x + u), d(x + v)
            node = np.where(probed[0] - probed[1] <= fields[4], nodes[6], nodes[5])
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
