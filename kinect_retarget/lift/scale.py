"""The per-frame scale s of the scaled orthographic camera (paper 004 eq. 2 and eq. 3), in pixels per metre.

Eq. 2: a bone's image length d can never exceed s times its 3D length L, so s >= max(d / L) in every frame.
Eq. 3 (the paper): s_{i+1} is the value, allowed by eq. 2, that keeps the bones' in-plane lengths d/s
closest to the previous frame's. "envelope" (our default) uses the same bound over the whole take: at some
moment within about a second most bodies hold a bone parallel to the image, where d/L reaches s, so a
smooth upper envelope of the per-frame bounds follows s without the paper's frame-to-frame drift.
"""
from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .tracks2d import LiftError

# Long bones whose image length bounds the scale (short or synthesised bones are too noisy).
SCALE_BONES = ("ShoulderLeft", "ShoulderRight", "ElbowLeft", "WristLeft", "ElbowRight", "WristRight",
               "KneeLeft", "AnkleLeft", "KneeRight", "AnkleRight")


def scale_lower_bound(d_px: np.ndarray, lengths: np.ndarray, usable: np.ndarray) -> np.ndarray:
    """Eq. 2 per frame: max over usable bones of d / L. d_px, usable (F, B); lengths (B,). NaN if none."""
    ratio = np.where(usable, d_px / np.maximum(lengths, 1e-9), -np.inf)
    out = ratio.max(axis=1)
    out[~np.isfinite(out)] = np.nan
    return out


def fill_missing(s: np.ndarray, source: str) -> np.ndarray:
    ok = np.isfinite(s)
    if not ok.any():
        raise LiftError(f"{source}: no frame shows a limb completely (shoulder, elbow, wrist, hip, knee, "
                        f"ankle): the body's scale cannot be measured")
    idx = np.arange(len(s))
    return np.interp(idx, idx[ok], s[ok])


def scale_paper(d_px: np.ndarray, lengths: np.ndarray, s_min: np.ndarray) -> np.ndarray:
    """Eq. 3: s_{i+1} = argmin_s sum_j (d_j,i / s_i - d_j,i+1 / s)^2 subject to s >= s_min,i+1.

    With w = 1/s the objective is a quadratic in w, minimised at w* = sum(a d) / sum(d^2), a = d_i / s_i.
    """
    s = np.empty_like(s_min)
    s[0] = s_min[0]
    d = np.nan_to_num(d_px)
    for i in range(1, len(s)):  # recursive by definition
        a = d[i - 1] / s[i - 1]
        den = float(np.dot(d[i], d[i]))
        w = float(np.dot(a, d[i])) / den if den > 0 else 1.0 / s[i - 1]
        s[i] = max(1.0 / w if w > 0 else s[i - 1], s_min[i])
    return s


def smooth_lengths(d_px: np.ndarray, usable: np.ndarray, window: int = 5) -> np.ndarray:
    """Rolling median of image bone lengths (F, B) over `window` frames: 2D jitter inflates lengths, and
    the envelope below reads their upper tail."""
    f = d_px.shape[0]
    if f < window:
        return d_px
    x = np.where(usable, d_px, np.nan)
    pad = np.pad(x, ((window // 2, window // 2), (0, 0)), mode="edge")
    win = sliding_window_view(pad, window, axis=0)
    with np.errstate(all="ignore"):
        med = np.nanmedian(np.where(np.isfinite(win).any(axis=-1, keepdims=True), win, 0.0), axis=-1)
    return np.where(usable, med, d_px)


def scale_envelope(ratios: np.ndarray, times: np.ndarray, window_s: float = 1.0,
                   quantile: float = 0.9) -> np.ndarray:
    """A smooth upper envelope of the eq. 2 ratios d/L (F, B) (NaN where unusable): a high quantile of all
    bones' ratios within a sliding window, then a rolling mean. A quantile rather than the maximum, so a
    few bad 2D points or a bone whose real length differs from the model do not inflate s."""
    f = ratios.shape[0]
    dt = float(np.median(np.diff(times))) if f > 1 else 1.0 / 30
    w = int(max(1, min(f, round(window_s / dt))) | 1)  # odd window
    pad = np.pad(ratios, ((w // 2, w // 2), (0, 0)), mode="edge")
    win = sliding_window_view(pad, w, axis=0).reshape(f, -1)
    q = fill_missing(np.nanquantile(np.where(np.isfinite(win), win, np.nan), quantile, axis=1)
                     if np.isfinite(win).any() else np.full(f, np.nan), "2D tracks")
    pad = np.pad(q, w // 2, mode="edge")
    return sliding_window_view(pad, w).mean(axis=1)
