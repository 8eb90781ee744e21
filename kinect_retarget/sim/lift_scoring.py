"""Measuring a lift against ground truth: synthetic 2D from a 3D take, MPJPE, Procrustes, sign flips."""
from __future__ import annotations

import numpy as np

from ..core.skeletons import NOT_TRACKED
from ..core.take import Take
from ..lift.video_camera import Camera
from ..lift.tracks2d import Tracks2D


def tracks_from_take(take: Take, camera: Camera, image_size: tuple[float, float],
                     noise_px: float = 0.0, rng: np.random.Generator | None = None) -> Tracks2D:
    """Project a take (already in the video camera's space) to 2D keypoints, with optional pixel noise."""
    uv = camera.project(take.positions)
    if noise_px > 0:
        uv = uv + (rng or np.random.default_rng(0)).normal(0.0, noise_px, uv.shape)
    conf = np.where(take.states != NOT_TRACKED, 1.0, 0.0)
    return Tracks2D(uv, conf, take.times, image_size, source="synthetic")


def procrustes_align(pred: np.ndarray, truth: np.ndarray, scale: bool = True) -> np.ndarray:
    """Per frame, the similarity transform of pred (F, J, 3) that best fits truth (Umeyama)."""
    mp, mt = pred.mean(axis=1, keepdims=True), truth.mean(axis=1, keepdims=True)
    a, b = pred - mp, truth - mt
    u, sv, vt = np.linalg.svd(np.einsum("fji,fjk->fik", a, b))
    d = np.sign(np.linalg.det(np.einsum("fij,fjk->fik", u, vt)))
    fix = np.ones_like(sv)
    fix[:, -1] = d
    rot = np.einsum("fij,fj,fjk->fik", u, fix, vt)  # maps a's rows: a @ rot
    k = np.sum(sv * fix, axis=1) / np.maximum(np.sum(a * a, axis=(1, 2)), 1e-12) if scale else np.ones(len(a))
    return k[:, None, None] * np.einsum("fji,fik->fjk", a, rot) + mt


def mpjpe(pred: np.ndarray, truth: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Mean per-joint position error (same units as the inputs) over the masked samples."""
    err = np.linalg.norm(pred - truth, axis=-1)
    return float(np.nanmean(err if mask is None else err[mask]))


def root_relative(p: np.ndarray, root: int = 0) -> np.ndarray:
    return p - p[:, root:root + 1]


def _depth_order(pred, truth, parents, bones, min_depth_m):
    """(wrong, clear) per (frame, bone): the child's depth offset from its parent has the wrong sign; the
    true offset is clearly out of the image plane."""
    dz_p = pred[:, bones, 2] - pred[:, parents[bones], 2]
    dz_t = truth[:, bones, 2] - truth[:, parents[bones], 2]
    return np.sign(dz_p) != np.sign(dz_t), np.abs(dz_t) > min_depth_m


def sign_error_rate(pred: np.ndarray, truth: np.ndarray, parents: np.ndarray, bones: np.ndarray,
                    min_depth_m: float = 0.05) -> float:
    """Fraction of (frame, bone) samples, among bones clearly out of the image plane, whose depth order
    (child nearer or farther than its parent) is wrong."""
    wrong, clear = _depth_order(pred, truth, parents, bones, min_depth_m)
    return float(np.mean(wrong[clear])) if clear.any() else 0.0


def sign_flip_fraction(pred: np.ndarray, truth: np.ndarray, parents: np.ndarray, bones: np.ndarray,
                       min_depth_m: float = 0.05) -> float:
    """Fraction of frames where some bone's depth offset has the wrong sign (where it is clearly nonzero)."""
    wrong, clear = _depth_order(pred, truth, parents, bones, min_depth_m)
    return float(np.mean((wrong & clear).any(axis=1)))


def ray_sides(positions: np.ndarray, parents: np.ndarray, camera: Camera | None) -> np.ndarray:
    """(F, J) the true depth signs in the lifter's sense: on which side of the point of its image ray
    (orthographic line when camera is None) nearest to its parent each joint lies (+1 farther)."""
    p = np.asarray(positions, dtype=np.float64)
    par = p[:, np.maximum(parents, 0)]
    if camera is None:
        u = np.broadcast_to([0.0, 0.0, 1.0], p.shape)
    else:
        u = p / np.linalg.norm(p, axis=-1, keepdims=True)
    along = np.sum((p - par) * u, axis=-1)
    return np.where(along >= 0, 1.0, -1.0)
