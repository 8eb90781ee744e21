"""Short gaps in 2D tracks (occlusion, a missed detection) filled by interpolation and marked inferred."""
from __future__ import annotations

import numpy as np


def fill_gaps(uv: np.ndarray, present: np.ndarray, times: np.ndarray, max_gap_s: float):
    """Linearly interpolate missing (F, J, 2) samples inside gaps no longer than max_gap_s.

    Returns (uv filled, filled mask (F, J)): only gaps with measured samples on both sides are filled, so
    nothing is extrapolated past the ends of a track.
    """
    out = uv.copy()
    filled = np.zeros(present.shape, dtype=bool)
    for j in range(present.shape[1]):  # a handful of joints; each is vectorised over frames
        ok = present[:, j]
        if ok.sum() < 2 or ok.all():
            continue
        idx = np.flatnonzero(ok)
        t_ok = times[idx]
        nxt = np.searchsorted(t_ok, times)  # first measured sample at or after each frame
        inside = (~ok) & (nxt > 0) & (nxt < len(idx))
        gap = np.full(len(times), np.inf)
        gap[inside] = t_ok[nxt[inside]] - t_ok[nxt[inside] - 1]
        use = inside & (gap <= max_gap_s)
        for c in range(2):
            out[use, j, c] = np.interp(times[use], t_ok, uv[idx, j, c])
        filled[use, j] = True
    return out, filled
