"""From an assembled packed frame to images: unpack the 11-bit pixels, blank what was lost, convert to mm."""
from __future__ import annotations

import numpy as np

from .depth_unpack import blank_byte_ranges, unpack_11bit
from .reassembly import AssembledFrame


def decode_frame(frame: AssembledFrame, mm_table: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """(raw (480, 640) uint16 with 2047 = no reading, mm (480, 640) uint16 with 0 = no reading, or None)."""
    raw = unpack_11bit(frame.packed)
    if frame.holes:
        blank_byte_ranges(raw, frame.holes)     # pixels straddling a lost packet are not readings
    return raw, (mm_table[raw] if mm_table is not None else None)
