"""Where the visible surface of a limb ends is not always where the limb ends: at the image's edge it leaves
the view, and beside a nearer surface it goes on behind the body. Such an extremity is not a hand or foot."""
from __future__ import annotations


BORDER_CELLS = 2       # an extremity this close to the image's edge may be where the limb leaves it
OCCLUDER_GAP = 0.06    # m nearer than the extremity for a neighbour to count as hiding the limb
OCCLUDER_RADIUS = 4    # cells around the extremity searched for a nearer surface (about 5 cm at 1.7 m)


def at_image_border(grid, rc) -> bool:
    """Grid cell (row, col) of the full depth grid within BORDER_CELLS of its edge."""
    h, w = grid.valid.shape
    r, c = rc
    return bool(r >= h - 1 - BORDER_CELLS or c <= BORDER_CELLS or c >= w - 1 - BORDER_CELLS or r <= BORDER_CELLS)


def occluded_end(xyz, mask, rc, radius: int = OCCLUDER_RADIUS) -> bool:
    """The surface next to this extremity is nearer the sensor: the limb goes on behind it, or into it (a
    hand resting on a thigh merges with it, and the surface's extremity is then the wrist)."""
    r, c = rc
    h, w = mask.shape
    win = (slice(max(r - radius, 0), min(r + radius + 1, h)), slice(max(c - radius, 0), min(c + radius + 1, w)))
    nearer = mask[win] & (xyz[win][..., 2] < xyz[r, c, 2] - OCCLUDER_GAP)
    return int(nearer.sum()) >= 2
