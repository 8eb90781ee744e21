"""A bone's depth magnitude from its image length, aware of 2D noise.

Paper 004: dz = sqrt(L^2 - d^2 / s^2). Near the image plane (d close to s L) that square root turns a pixel of
jitter into centimetres of depth, and a bone measured longer than L gets dz = 0 exactly. We use instead the
posterior mean of dz given the measured foreshortening c = d / (s L), with c observed with Gaussian noise
of the tracks' own jitter and a uniform prior on the bone's depth direction (uniform dz / L for a
direction uniform on the sphere).
"""
from __future__ import annotations

import numpy as np

_U = (np.arange(48) + 0.5) / 48          # dz / L grid over [0, 1]
_C = np.sqrt(1.0 - _U ** 2)             # foreshortening of each grid value


def depth_magnitude(c_obs: np.ndarray, sigma_c: np.ndarray | float) -> np.ndarray:
    """E[dz / L | c_obs] (same shape as c_obs); sigma_c: noise of c_obs (broadcastable). sigma 0 gives
    the paper's sqrt(1 - c^2)."""
    c = np.asarray(c_obs, dtype=np.float64)
    sig = np.broadcast_to(np.asarray(sigma_c, dtype=np.float64), c.shape)
    exact = np.sqrt(np.maximum(0.0, 1.0 - np.minimum(c, 1.0) ** 2))
    noisy = sig > 1e-6
    if not noisy.any():
        return exact
    cn, sn = c[noisy][:, None], sig[noisy][:, None]
    w = np.exp(-0.5 * ((cn - _C) / sn) ** 2)
    den = w.sum(axis=1)
    post = np.where(den > 1e-300, (w * _U).sum(axis=1) / np.maximum(den, 1e-300), exact[noisy])
    out = exact.copy()
    out[noisy] = post
    return out


def jitter_px(uv: np.ndarray, valid: np.ndarray) -> float:
    """Robust per-coordinate 2D noise (px) from second differences: white noise of std s gives 6 s^2."""
    d2 = uv[2:] - 2 * uv[1:-1] + uv[:-2]
    ok = valid[2:] & valid[1:-1] & valid[:-2]
    x = d2[ok].ravel()
    x = x[np.isfinite(x)]
    if x.size < 10:
        return 0.0
    return float(1.4826 * np.median(np.abs(x - np.median(x))) / np.sqrt(6.0))
