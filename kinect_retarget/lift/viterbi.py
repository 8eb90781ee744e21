"""Min-sum Viterbi over a chain of frames with a small discrete state per frame."""
from __future__ import annotations

import numpy as np


def viterbi(unary: np.ndarray, pairwise: np.ndarray) -> np.ndarray:
    """unary (F, S) costs, pairwise (F-1, S, S) costs [previous state, next state] -> (F,) best states.

    The forward pass is inherently sequential over frames; each step is vectorised over the S x S pairs.
    """
    f, s = unary.shape
    if f == 0:
        return np.zeros(0, dtype=np.int64)
    back = np.zeros((f, s), dtype=np.int64)
    acc = unary[0].copy()
    for t in range(1, f):
        total = acc[:, None] + pairwise[t - 1]
        back[t] = np.argmin(total, axis=0)
        acc = total[back[t], np.arange(s)] + unary[t]
    path = np.empty(f, dtype=np.int64)
    path[-1] = int(np.argmin(acc))
    for t in range(f - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    return path

