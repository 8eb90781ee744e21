"""Where a limb's visible surface ends is not always where the limb ends: the image's edge (tested in
test_tracker) and a nearer body part hiding the rest of it (depth/limb_ends.py)."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth.segmentation import DepthGrid
from kinect_retarget.depth.limb_ends import occluded_end as _occluded_end


def _person(seq, camera, i=0):
    grid = DepthGrid.from_mm(seq.mm[i], camera, 4)
    hip = seq.joints[i][KINECT_V1.index("HipCenter")]
    mask = grid.valid & (np.abs(grid.xyz[..., 2] - hip[2]) < 0.6) & (np.abs(grid.xyz[..., 0] - hip[0]) < 0.8)
    return grid, mask


def _cell(grid, p):
    r, c = np.round(grid.to_pixel(p)).astype(int)
    return int(r), int(c)


def test_head_top_is_a_free_end(rendered, camera):
    seq, _ = rendered
    grid, mask = _person(seq, camera)
    r, c = _cell(grid, seq.joints[0][KINECT_V1.index("Head")])
    while r > 0 and mask[r - 1, c]:
        r -= 1                     # up to the top of the skull, where the surface ends against the wall
    assert mask[r, c] and not _occluded_end(grid.xyz, mask, (r, c))


def test_a_nearer_surface_beside_the_end_hides_the_rest(rendered, camera):
    seq, _ = rendered
    grid, mask = _person(seq, camera)
    r, c = _cell(grid, seq.joints[0][KINECT_V1.index("Head")])
    while r > 0 and mask[r - 1, c]:
        r -= 1
    xyz, mask = grid.xyz.copy(), mask.copy()
    # something 25 cm nearer the sensor just above the skull (a raised hand in front of it)
    xyz[r - 2:r, c - 1:c + 2, 2] = xyz[r, c, 2] - 0.25
    mask[r - 2:r, c - 1:c + 2] = True
    assert _occluded_end(xyz, mask, (r, c))
    # but a surface behind it (the wall, or the chest behind a hand) hides nothing
    xyz[r - 2:r, c - 1:c + 2, 2] = xyz[r, c, 2] + 0.25
    assert not _occluded_end(xyz, mask, (r, c))
