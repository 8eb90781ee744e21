"""Gaussian smoothing over time that respects gaps (normalised convolution: missing samples weigh 0)."""
from __future__ import annotations

import numpy as np


def gaussian_kernel(times: np.ndarray, sigma_s: float) -> np.ndarray | None:
    """The unnormalised Gaussian taps (2r + 1, r = ceil(3 sigma)) for sigma_s seconds at the median frame
    interval of times (at least two), or None when sigma is under 0.3 frame: smoothing would change nothing."""
    dt = float(np.median(np.diff(times)))
    sig = sigma_s / dt
    if sig < 0.3:
        return None
    r = int(np.ceil(3 * sig))
    return np.exp(-0.5 * (np.arange(-r, r + 1) / sig) ** 2)


def gaussian_smooth(x: np.ndarray, valid: np.ndarray, times: np.ndarray, sigma_s: float) -> np.ndarray:
    """Smooth x (F, ...) along frames with a Gaussian of sigma_s seconds; valid (F, ...) marks real samples
    (broadcastable to x). Invalid samples keep their value and do not leak into their neighbours."""
    f = x.shape[0]
    if sigma_s <= 0 or f < 3:
        return x
    k = gaussian_kernel(times, sigma_s)
    if k is None:
        return x
    r = len(k) // 2
    m = np.broadcast_to(valid, x.shape).astype(np.float64)
    xv = np.where(m > 0, x, 0.0)
    flat_x = xv.reshape(f, -1)
    flat_m = m.reshape(f, -1)
    conv = lambda c: np.convolve(c, k, "full")[r:r + f]  # noqa: E731  (centred; any length)
    num = np.apply_along_axis(conv, 0, flat_x)
    den = np.apply_along_axis(conv, 0, flat_m)
    out = np.where(den > 1e-9, num / np.maximum(den, 1e-9), flat_x).reshape(x.shape)
    return np.where(m > 0, out, x)
