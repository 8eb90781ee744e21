"""A take whose feet point down more steeply than any rig's rest foot: each Foot joint turned down about its
ankle by a fixed angle (Kinect camera space, Y up), so a bake dips the toes under the floor unless the feet
pass lifts them. Built at test time from a repository take."""
from __future__ import annotations

import copy

import numpy as np


def steep_feet(take, degrees: float = 40.0):
    out = copy.deepcopy(take)
    sk, p = out.skeleton, out.positions
    up = np.array([0.0, 1.0, 0.0])
    for side in ("Left", "Right"):
        a, f = sk.index("Ankle" + side), sk.index("Foot" + side)
        d = p[:, f] - p[:, a]
        n = np.linalg.norm(d, axis=-1, keepdims=True)
        fwd = d - np.outer(d @ up, up)
        fwd /= np.linalg.norm(fwd, axis=-1, keepdims=True)
        pitch = np.arctan2(d @ up, np.linalg.norm(d - np.outer(d @ up, up), axis=-1)) - np.radians(degrees)
        p[:, f] = p[:, a] + n * (np.cos(pitch)[:, None] * fwd + np.sin(pitch)[:, None] * up)
    return out
