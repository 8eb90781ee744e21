"""Foot contacts from a baked take (issue 16): a foot is planted while it moves slowly near the lowest height it
reaches, with hysteresis (stricter to enter a contact than to stay in it), so Kinect jitter neither splits a
stance nor invents one. Positions are the target rig's ankles in armature space; thresholds scale with its
leg length. Also the blend weights that ease a pin in and out over a few frames. Pure numpy.
"""
from __future__ import annotations

import numpy as np

LOW_PERCENTILE = 5       # "the lowest height the foot reaches": a low percentile (a glitch is not the floor)
ENTER_HEIGHT = 0.06      # enter a contact below low + this x leg length ...
EXIT_HEIGHT = 0.12       # ... leave it above low + this x leg length
ENTER_SPEED = 0.25       # enter below this many leg lengths per second ...
EXIT_SPEED = 0.5         # ... leave above this (a foot shuffled over the floor is not planted)
SMOOTH_S = 0.1           # speed from positions this many seconds apart (central difference)
MIN_CONTACT_S = 0.1      # shorter stances are noise
RAMP_S = 0.15            # pins ease in before and out after a contact over this long


def foot_speed(pos: np.ndarray, rate: float) -> np.ndarray:
    """(F,) speed of (F, 3) positions, m/s, by central differences SMOOTH_S apart."""
    h = max(1, int(round(SMOOTH_S * rate / 2)))
    padded = np.concatenate([np.repeat(pos[:1], h, 0), pos, np.repeat(pos[-1:], h, 0)])
    return np.linalg.norm(padded[2 * h:] - padded[:-2 * h], axis=-1) * rate / (2 * h)


def detect_contacts(pos: np.ndarray, up: np.ndarray, leg: float, rate: float) -> np.ndarray:
    """(F,) bool: the foot at (F, 3) positions is planted (hysteresis on height and speed)."""
    height = pos @ up
    low = np.percentile(height, LOW_PERCENTILE)
    speed = foot_speed(pos, rate)
    enter = (height < low + ENTER_HEIGHT * leg) & (speed < ENTER_SPEED * leg)
    stay = (height < low + EXIT_HEIGHT * leg) & (speed < EXIT_SPEED * leg)
    out = np.zeros(len(pos), bool)
    on = False
    for f in range(len(pos)):
        on = bool(stay[f]) if on else bool(enter[f])
        out[f] = on
    return drop_short(out, max(2, int(round(MIN_CONTACT_S * rate))))


def intervals(mask: np.ndarray) -> list[tuple[int, int]]:
    """[(first, last)] frame index ranges where mask is True."""
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1))


def drop_short(mask: np.ndarray, shortest: int) -> np.ndarray:
    out = mask.copy()
    for a, b in intervals(mask):
        if b - a + 1 < shortest:
            out[a:b + 1] = False
    return out


def pin_weights(mask: np.ndarray, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """(weights (F,), contact index (F,), -1 for none): 1 during each contact, easing (smoothstep) to 0 over
    RAMP_S before and after it; where two ramps overlap the nearer contact wins."""
    n = len(mask)
    ramp = max(2, int(round(RAMP_S * rate)))
    w, which = np.zeros(n), np.full(n, -1)
    for c, (a, b) in enumerate(intervals(mask)):
        f = np.arange(max(0, a - ramp), min(n, b + ramp + 1))
        dist = np.maximum(np.maximum(a - f, f - b), 0)
        x = 1 - dist / (ramp + 1)
        wc = x * x * (3 - 2 * x)
        better = wc > w[f]
        w[f[better]], which[f[better]] = wc[better], c
    return w, which
