"""The paper's 2D joint tracker (paper 004 §2): joints marked on the first frame, each followed by a particle
filter whose prediction seeds a colour-histogram template match (Bhattacharyya criterion).

Per joint and frame: particles move by the joint's last velocity plus noise; each is weighted by how well
the colour histogram of the window around it matches the joint's template (weight exp(-(1 - rho) / 2s^2),
rho the Bhattacharyya coefficient); the weighted mean starts a local search on a pixel grid, and the most
similar window is the joint's position (the paper's "maximum similarity"). When even that similarity is
low the joint is reported lost for the frame (confidence 0) and the filter coasts and widens its search
until the colours match again. The template follows slow appearance changes when the match is good.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass

import numpy as np

from .clip_naming import joint_for_track
from .openpose import write_frame
from .schemes import BODY_25
from .tracks2d import LiftError

BINS = 8  # per RGB channel


@dataclass(frozen=True)
class TrackerSettings:
    particles: int = 150
    half: int = 15               # template window half-size, pixels
    motion_px: float = 6.0       # particle spread per frame, pixels
    search_px: int = 6           # local template search radius around the particle estimate
    sigma_b: float = 0.12        # Bhattacharyya distance scale of particle weights
    lost_below: float = 0.55     # Bhattacharyya coefficient under which a joint is lost
    adapt: float = 0.05          # template update rate when the match is good
    seed: int = 0


@dataclass
class TrackResult:
    uv: np.ndarray       # (K, 2) pixels
    similarity: np.ndarray  # (K,) Bhattacharyya coefficient of the chosen window
    found: np.ndarray    # (K,) bool


class JointTracker:
    def __init__(self, first: np.ndarray, init: dict[str, tuple[float, float]],
                 settings: TrackerSettings = TrackerSettings()):
        if not init:
            raise LiftError("tracker init names no joints")
        self.s = settings
        self.names = tuple(init)
        self.rng = np.random.default_rng(settings.seed)
        self.pos = np.array([init[n] for n in self.names], dtype=np.float64)
        h, w = first.shape[:2]
        bad = [n for n, p in zip(self.names, self.pos) if not (0 <= p[0] < w and 0 <= p[1] < h)]
        if bad:
            raise LiftError(f"tracker init: {', '.join(bad)} outside the {w}x{h} first frame")
        self.vel = np.zeros_like(self.pos)
        self.lost = np.zeros(len(self.names), dtype=bool)
        hh = settings.half
        g = np.arange(-hh, hh + 1, 2, dtype=np.float64)  # every other pixel: plenty for a histogram
        oy, ox = np.meshgrid(g, g, indexing="ij")
        self.offsets = np.stack([ox.ravel(), oy.ravel()], axis=1)
        r2 = np.sum(self.offsets ** 2, axis=1) / (hh * hh)
        self.kernel = np.maximum(1.0 - r2, 0.0)  # Epanechnikov: the window's centre counts most
        r = np.arange(-settings.search_px, settings.search_px + 1, 2, dtype=np.float64)
        gy, gx = np.meshgrid(r, r, indexing="ij")
        self.grid = np.stack([gx.ravel(), gy.ravel()], axis=1)  # template search offsets around the estimate
        q = _quantise(first)
        self.templates = self._histograms(q, self.pos)
        self.particles = np.repeat(self.pos[:, None, :], settings.particles, axis=1)

    def initial(self) -> TrackResult:
        return TrackResult(self.pos.copy(), np.ones(len(self.names)), np.ones(len(self.names), dtype=bool))

    def step(self, frame: np.ndarray) -> TrackResult:
        s = self.s
        q = _quantise(frame)
        h, w = q.shape
        k, n = len(self.names), s.particles
        spread = s.motion_px * np.where(self.lost, 3.0, 1.0)[:, None, None]
        # predict: resampled particles move with the joint's velocity, plus noise
        self.particles = self.particles + self.vel[:, None, :] + self.rng.normal(0, 1, (k, n, 2)) * spread
        self.particles[..., 0] = np.clip(self.particles[..., 0], 0, w - 1)
        self.particles[..., 1] = np.clip(self.particles[..., 1], 0, h - 1)
        rho = self._rho(q, self.particles.reshape(-1, 2), np.repeat(np.arange(k), n)).reshape(k, n)
        wts = np.exp(-(1.0 - rho) / (2 * s.sigma_b ** 2))
        wts /= np.maximum(wts.sum(axis=1, keepdims=True), 1e-300)
        estimate = np.einsum("kn,knc->kc", wts, self.particles)
        # template match around the prediction: the most similar window wins
        grid = self.grid
        cand = estimate[:, None, :] + grid[None]
        cand[..., 0] = np.clip(cand[..., 0], 0, w - 1)
        cand[..., 1] = np.clip(cand[..., 1], 0, h - 1)
        crho = self._rho(q, cand.reshape(-1, 2), np.repeat(np.arange(k), len(grid))).reshape(k, len(grid))
        best = np.argmax(crho, axis=1)
        new = cand[np.arange(k), best]
        sim = crho[np.arange(k), best]
        found = sim >= s.lost_below
        self.vel = np.where(found[:, None], 0.5 * self.vel + 0.5 * (new - self.pos), self.vel)
        self.pos = np.where(found[:, None], new, self.pos + self.vel)
        self.lost = ~found
        good = sim > 0.8
        if good.any():  # follow slow changes of appearance
            hist = self._histograms(q, new[good])
            self.templates[good] = (1 - s.adapt) * self.templates[good] + s.adapt * hist
        # resample (systematic) for the next frame
        u = (self.rng.random((k, 1)) + np.arange(n)) / n
        idx = np.minimum(np.array([np.searchsorted(np.cumsum(wk), uk) for wk, uk in zip(wts, u)]), n - 1)
        self.particles = np.take_along_axis(self.particles, idx[..., None], axis=1)
        return TrackResult(self.pos.copy(), sim, found)

    def _histograms(self, q: np.ndarray, centres: np.ndarray) -> np.ndarray:
        h, w = q.shape
        pts = np.round(centres[:, None, :] + self.offsets[None]).astype(np.int64)
        inside = (pts[..., 0] >= 0) & (pts[..., 0] < w) & (pts[..., 1] >= 0) & (pts[..., 1] < h)
        bins = q[np.clip(pts[..., 1], 0, h - 1), np.clip(pts[..., 0], 0, w - 1)]
        m = centres.shape[0]
        wt = np.where(inside, self.kernel[None], 0.0)
        hist = np.bincount((np.arange(m)[:, None] * BINS ** 3 + bins).ravel(), wt.ravel(),
                           minlength=m * BINS ** 3).reshape(m, BINS ** 3)
        return hist / np.maximum(hist.sum(axis=1, keepdims=True), 1e-12)

    def _rho(self, q, centres, joint_of) -> np.ndarray:
        """Bhattacharyya coefficient between each window's histogram and its joint's template."""
        return np.sum(np.sqrt(self._histograms(q, centres) * self.templates[joint_of]), axis=1)


def _quantise(img: np.ndarray) -> np.ndarray:
    c = np.clip((np.asarray(img)[..., :3] * BINS).astype(np.int64), 0, BINS - 1)
    return (c[..., 0] * BINS + c[..., 1]) * BINS + c[..., 2]


# Kinect v1 joints written as BODY_25 keypoints (the OpenPose reader maps them back).
_BODY25_OF_V1 = {"HipCenter": "MidHip", "ShoulderCenter": "Neck", "Head": "Nose",
                 **{f"{p}{s}": f"{s[0]}{p}" for s in ("Left", "Right")
                    for p in ("Shoulder", "Elbow", "Wrist", "Hip", "Knee", "Ankle")},
                 "FootLeft": "LBigToe", "FootRight": "RBigToe"}


def read_init(path: str) -> dict[str, tuple[float, float]]:
    """{joint name: [u, v]} (or {"joints": {...}}) in first-frame pixels; names as for clip tracks."""
    try:
        with open(path, "r", encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, json.JSONDecodeError) as exc:
        raise LiftError(f"{path}: cannot read tracker init ({exc})") from None
    data = data.get("joints", data) if isinstance(data, dict) else None
    if not isinstance(data, dict) or not data:
        raise LiftError(f"{path}: expected {{joint name: [u, v], ...}}")
    out = {}
    for name, uv in data.items():
        try:
            u, v = (float(x) for x in uv)
        except (TypeError, ValueError):
            raise LiftError(f"{path}: joint {name!r}: expected [u, v] pixels") from None
        out[name] = (u, v)
    return out


def body25_index(name: str) -> int | None:
    if name in BODY_25:
        return BODY_25.index(name)
    joint = joint_for_track(name)
    b = _BODY25_OF_V1.get(joint or "")
    return BODY_25.index(b) if b else None


def write_keypoints(folder: str, frame_paths: list[str], results: list[TrackResult], names) -> int:
    """One OpenPose BODY_25 file per frame; joints without a BODY_25 keypoint are left out (reported)."""
    idx = [body25_index(n) for n in names]
    missing = [n for n, i in zip(names, idx) if i is None]
    if len(missing) == len(names):
        raise LiftError(f"none of the tracked joints has an OpenPose BODY_25 keypoint: {', '.join(missing)}")
    os.makedirs(folder, exist_ok=True)
    for f, (path, r) in enumerate(zip(frame_paths, results)):
        uv = np.zeros((len(BODY_25), 2))
        conf = np.zeros(len(BODY_25))
        for k, i in enumerate(idx):
            if i is not None and r.found[k]:
                uv[i], conf[i] = r.uv[k], max(float(r.similarity[k]), 1e-3)
        stem = os.path.splitext(os.path.basename(path))[0]
        write_frame(os.path.join(folder, f"{stem}_{f:012d}_keypoints.json"), uv, conf)
    return len(frame_paths)
