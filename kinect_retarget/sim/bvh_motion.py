"""BVH joint positions per frame, for posing the synthetic body: the project's BVH reader (takes/bvh.py) with
end sites left out and a fixed unit (CMU's by default), as the renderer's body poser expects."""
from __future__ import annotations

import os

import numpy as np

from ..takes.bvh import read_bvh_skeleton

CMU_UNIT_M = 0.0564  # 1 CMU unit = 1/0.45 inch (data/README.md §3)


def read_bvh_positions(path: str | os.PathLike, unit: float = CMU_UNIT_M):
    """Return (names, parents, positions (F, J, 3) metres in BVH world axes, frame_time) of the joints that
    carry channels (end sites left out). A bad file raises TakeError naming it."""
    motion = read_bvh_skeleton(path, scale=unit)
    sk = motion.skeleton
    keep = np.flatnonzero(~sk.is_end_site)
    new_index = {int(j): k for k, j in enumerate(keep)}
    names = [sk.names[j] for j in keep]
    parents = [new_index[int(sk.parents[j])] if sk.parents[j] >= 0 else -1 for j in keep]
    return names, parents, motion.positions[:, keep] * unit, motion.frame_time
