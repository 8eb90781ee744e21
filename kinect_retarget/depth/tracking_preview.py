"""Depth preview image with the segmented person and the fitted skeleton drawn over it (pure numpy).

The sidebar uploads the result into a Blender image from the main thread; building it here keeps that code
to one `image.pixels.foreach_set`. Rows are bottom-up, as Blender images are.
"""
from __future__ import annotations

import numpy as np

from ..core.conventions import kinect_to_depth_pixel
from ..core.skeletons import KINECT_V1, NOT_TRACKED, TRACKED
from .depth_camera import DepthCamera

_TRACKED = np.array([1.0, 0.85, 0.1, 1.0])
_INFERRED = np.array([0.9, 0.3, 0.9, 1.0])


def preview_rgba(depth_mm: np.ndarray, person_mask: np.ndarray | None, positions: np.ndarray, states: np.ndarray,
                 camera: DepthCamera | None = None, scale: int = 2) -> np.ndarray:
    """(H/scale, W/scale, 4) float32 RGBA: grey depth, the person tinted green, bones and joints coloured
    by tracking state (yellow tracked, magenta inferred)."""
    cam = camera or DepthCamera()
    d = np.asarray(depth_mm)[::scale, ::scale].astype(np.float32)
    h, w = d.shape
    grey = np.where(d > 0, 1.0 - np.clip((d - 500.0) / 4500.0, 0, 1) * 0.8, 0.0)
    img = np.zeros((h, w, 4), np.float32)
    img[..., :3] = grey[..., None]
    img[..., 3] = 1.0
    if person_mask is not None and person_mask.any():
        k = max(1, int(round(h / person_mask.shape[0])))
        m = np.kron(person_mask, np.ones((k, k), bool))[:h, :w]
        img[:m.shape[0], :m.shape[1]][m] *= np.array([0.5, 1.0, 0.5, 1.0], np.float32)
    pos, st = np.asarray(positions, dtype=np.float64), np.asarray(states)
    ok = (st != NOT_TRACKED) & np.all(np.isfinite(pos), axis=1) & (pos[:, 2] > 0.1)
    uv = np.zeros((len(pos), 2))
    uv[ok] = kinect_to_depth_pixel(pos[ok], cam.f, cam.cx, cam.cy) / scale
    t = np.linspace(0.0, 1.0, 24)[:, None]
    for j, p in enumerate(KINECT_V1.parents):
        if p < 0 or not (ok[j] and ok[p]):
            continue
        line = uv[p] + t * (uv[j] - uv[p])
        _paint(img, line, _TRACKED if st[j] == TRACKED and st[p] == TRACKED else _INFERRED, 0)
    for j in np.flatnonzero(ok):
        _paint(img, uv[j:j + 1], _TRACKED if st[j] == TRACKED else _INFERRED, 2)
    return img[::-1].copy()


def _paint(img: np.ndarray, pts: np.ndarray, colour: np.ndarray, radius: int) -> None:
    h, w = img.shape[:2]
    r = np.arange(-radius, radius + 1)
    du, dv = np.meshgrid(r, r)
    u = (np.round(pts[:, 0])[:, None] + du.ravel()).astype(np.int64).ravel()
    v = (np.round(pts[:, 1])[:, None] + dv.ravel()).astype(np.int64).ravel()
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    img[v[inside], u[inside]] = colour
