"""A coloured body rendered from joint positions: test imagery for the 2D tracker (pure numpy).

Each bone is a capsule of its own colour (left and right limbs differ, as on the coloured suits such
trackers assume), drawn with a depth buffer through a pinhole camera; the head is a disc. The background
is a seeded, smoothly textured grey with pixel noise, so a histogram cannot match it by accident.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1
from ..lift.video_camera import Camera

SK = KINECT_V1
# (bone by child joint, radius in metres, RGB)
BODY = (
    ("Spine", 0.13, (0.55, 0.45, 0.35)), ("ShoulderCenter", 0.13, (0.55, 0.45, 0.35)),
    ("ShoulderLeft", 0.05, (0.55, 0.45, 0.35)), ("ShoulderRight", 0.05, (0.55, 0.45, 0.35)),
    ("HipLeft", 0.07, (0.35, 0.30, 0.30)), ("HipRight", 0.07, (0.35, 0.30, 0.30)),
    ("ElbowLeft", 0.045, (0.90, 0.15, 0.10)), ("WristLeft", 0.04, (0.95, 0.60, 0.10)),
    ("HandLeft", 0.045, (0.95, 0.90, 0.20)),
    ("ElbowRight", 0.045, (0.10, 0.25, 0.90)), ("WristRight", 0.04, (0.10, 0.80, 0.90)),
    ("HandRight", 0.045, (0.70, 0.95, 0.60)),
    ("KneeLeft", 0.07, (0.10, 0.65, 0.15)), ("AnkleLeft", 0.055, (0.60, 0.90, 0.10)),
    ("FootLeft", 0.045, (0.20, 0.35, 0.10)),
    ("KneeRight", 0.07, (0.75, 0.10, 0.75)), ("AnkleRight", 0.055, (0.45, 0.15, 0.60)),
    ("FootRight", 0.045, (0.35, 0.10, 0.35)),
)
HEAD_RADIUS, HEAD_RGB = 0.10, (0.95, 0.75, 0.60)


def background(width: int, height: int, rng: np.random.Generator) -> np.ndarray:
    coarse = rng.uniform(0.35, 0.65, (height // 16 + 2, width // 16 + 2, 3))
    yy = np.linspace(0, coarse.shape[0] - 1.001, height)
    xx = np.linspace(0, coarse.shape[1] - 1.001, width)
    y0, x0 = yy.astype(int), xx.astype(int)
    fy, fx = (yy - y0)[:, None, None], (xx - x0)[None, :, None]
    c = coarse
    img = ((1 - fy) * (1 - fx) * c[y0][:, x0] + (1 - fy) * fx * c[y0][:, x0 + 1]
           + fy * (1 - fx) * c[y0 + 1][:, x0] + fy * fx * c[y0 + 1][:, x0 + 1])
    return img.astype(np.float32)


def render(positions: np.ndarray, cam: Camera, width: int, height: int, bg: np.ndarray,
           rng: np.random.Generator | None = None, noise: float = 0.02) -> np.ndarray:
    """(H, W, 3) float32 image of one frame's joints (J, 3), Kinect camera space."""
    img = bg.copy()
    zbuf = np.full((height, width), np.inf)
    uv = cam.project(positions)
    for name, radius, rgb in BODY:
        j = SK.index(name)
        _capsule(img, zbuf, uv[SK.parents[j]], uv[j], positions[SK.parents[j], 2], positions[j, 2],
                 radius * cam.focal_px / positions[[SK.parents[j], j], 2], rgb)
    h = SK.index("Head")
    r = HEAD_RADIUS * cam.focal_px / positions[h, 2]
    _capsule(img, zbuf, uv[h], uv[h], positions[h, 2], positions[h, 2], np.array([r, r]), HEAD_RGB)
    if rng is not None and noise > 0:
        img = img + rng.normal(0, noise, img.shape).astype(np.float32)
    return np.clip(img, 0, 1)


def _capsule(img, zbuf, a, b, za, zb, radii, rgb) -> None:
    h, w = zbuf.shape
    r = float(max(radii))
    lo = np.floor(np.minimum(a, b) - r).astype(int)
    hi = np.ceil(np.maximum(a, b) + r).astype(int)
    x0, y0 = max(lo[0], 0), max(lo[1], 0)
    x1, y1 = min(hi[0], w - 1), min(hi[1], h - 1)
    if x1 < x0 or y1 < y0:
        return
    ys, xs = np.mgrid[y0:y1 + 1, x0:x1 + 1]
    p = np.stack([xs + 0.5, ys + 0.5], axis=-1)
    ab = b - a
    t = np.clip(np.sum((p - a) * ab, axis=-1) / max(float(ab @ ab), 1e-9), 0, 1)
    dist = np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)
    rad = radii[0] + t * (radii[1] - radii[0])
    z = za + t * (zb - za)
    inside = (dist <= rad) & (z < zbuf[y0:y1 + 1, x0:x1 + 1])
    shade = 0.75 + 0.25 * np.sqrt(np.clip(1 - (dist / np.maximum(rad, 1e-6)) ** 2, 0, 1))  # round look
    region = img[y0:y1 + 1, x0:x1 + 1]
    region[inside] = np.asarray(rgb, dtype=np.float32) * shade[inside][:, None]
    zbuf[y0:y1 + 1, x0:x1 + 1][inside] = z[inside]
