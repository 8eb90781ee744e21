"""Resample a baked motion onto a scene's frame grid: keys at the scene's rate (every `step` frames), rotations
by slerp and positions linearly between the take's samples, so a 30 fps take plays at its own speed in a 24 fps
scene without changing the scene."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .pipeline import BakedMotion
from .quat import make_continuous, normalize


def slerp(a: np.ndarray, b: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Spherical interpolation (..., 4) a -> b at u (...,), the short way (b's sign follows a)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    dot = np.sum(a * b, axis=-1)
    b = np.where(dot[..., None] < 0, -b, b)
    dot = np.abs(dot)
    u = np.asarray(u, dtype=np.float64)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    s = np.sin(theta)
    near = s < 1e-6  # nearly equal: linear is exact enough and avoids 0/0
    safe = np.where(near, 1.0, s)
    wa = np.where(near, 1 - u, np.sin((1 - u) * theta) / safe)
    wb = np.where(near, u, np.sin(u * theta) / safe)
    return normalize(wa[..., None] * a + wb[..., None] * b)


def grid(times: np.ndarray, rate: float, step: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Frame offsets (K,) multiples of `step` and their times (K,) covering times[0]..times[-1] (seconds from
    the take's start): the first and last offsets round to the nearest frame, times clamp to the samples'."""
    first = int(round(times[0] * rate / step))
    last = max(first, int(round(times[-1] * rate / step)))
    offsets = np.arange(first, last + 1) * step
    return offsets, np.clip(offsets / rate, times[0], times[-1])


def _bracket(times: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index i (K,) with times[i] <= at < times[i+1] (last interval at the end) and the fraction u (K,)."""
    if len(times) == 1:
        return np.zeros(len(at), dtype=np.int64), np.zeros(len(at))
    i = np.clip(np.searchsorted(times, at, side="right") - 1, 0, len(times) - 2)
    u = np.clip((at - times[i]) / (times[i + 1] - times[i]), 0.0, 1.0)
    return i, u


def interpolate_quats(times: np.ndarray, quats: np.ndarray, at: np.ndarray) -> np.ndarray:
    """quats (N, ..., 4) sampled at times (N,) -> (K, ..., 4) at `at` (K,) by slerp."""
    i, u = _bracket(times, at)
    if len(times) == 1:
        return quats[i].copy()
    u = u.reshape((-1,) + (1,) * (quats.ndim - 2))
    return slerp(quats[i], quats[i + 1], np.broadcast_to(u, quats[i].shape[:-1]))


def interpolate_values(times: np.ndarray, values: np.ndarray, at: np.ndarray) -> np.ndarray:
    """values (N, ...) sampled at times (N,) -> (K, ...) at `at` (K,), linearly."""
    i, u = _bracket(times, at)
    if len(times) == 1:
        return values[i].copy()
    u = u.reshape((-1,) + (1,) * (values.ndim - 1))
    return values[i] * (1 - u) + values[i + 1] * u


def resample_motion(motion: BakedMotion, times: np.ndarray, rate: float, frame_start: int,
                    step: int = 1) -> BakedMotion:
    """Motion whose keys sit on `frame_start + k·step` at `rate` fps; `times` (N,) are the seconds of the
    motion's keys from the take's start (the take's first sample is frame_start). Rotations (and the
    armature-space rotations kept for constrained rigs) by slerp, root location and joint positions linearly;
    `samples` names the take sample nearest each new key."""
    offsets, at = grid(times, rate, step)
    i, u = _bracket(times, at)
    nearest = np.minimum(i + (u >= 0.5), len(times) - 1) if len(times) > 1 else i
    extras = dict(motion.extras)
    if "desired" in extras:
        extras["desired"] = make_continuous(interpolate_quats(times, extras["desired"], at), axis=0)
    if "positions" in extras:
        extras["positions"] = interpolate_values(times, extras["positions"], at)
    return replace(motion, frames=frame_start + offsets,
                   quats=make_continuous(interpolate_quats(times, motion.quats, at), axis=0),
                   root_location=interpolate_values(times, motion.root_location, at), fps=float(rate),
                   samples=motion.samples[nearest], extras=extras)
