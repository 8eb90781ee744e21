"""The Kinect's 11-bit packed depth format: 8 pixels in 11 bytes, most significant bit first.

unpack_11bit turns the 422,400 bytes of one frame into a (480, 640) uint16 image; pack_11bit is its exact
inverse (the emulated device uses it to put real depth images on the wire).
"""
from __future__ import annotations

import numpy as np

from .protocol import DEPTH_FRAME_BYTES, DEPTH_HEIGHT, DEPTH_WIDTH

NO_READING_RAW = 2047


def unpack_11bit(packed, shape: tuple[int, int] = (DEPTH_HEIGHT, DEPTH_WIDTH)) -> np.ndarray:
    """Packed 11-bit stream (bytes-like or uint8 array, length 11/8 * pixels) -> uint16 image of `shape`."""
    data = np.frombuffer(packed, dtype=np.uint8) if not isinstance(packed, np.ndarray) else packed
    n_pixels = shape[0] * shape[1]
    if data.size != n_pixels * 11 // 8 or n_pixels % 8:
        raise ValueError(f"packed depth has {data.size} bytes, expected {n_pixels * 11 // 8} for {shape}")
    # Column views of each byte position within the 11-byte groups, widened once to uint16.
    r = data.reshape(-1, 11).T.astype(np.uint16)
    out = np.empty((r.shape[1], 8), dtype=np.uint16)
    out[:, 0] = (r[0] << 3) | (r[1] >> 5)
    out[:, 1] = ((r[1] << 6) | (r[2] >> 2)) & 0x7FF
    out[:, 2] = ((r[2] << 9) | (r[3] << 1) | (r[4] >> 7)) & 0x7FF
    out[:, 3] = ((r[4] << 4) | (r[5] >> 4)) & 0x7FF
    out[:, 4] = ((r[5] << 7) | (r[6] >> 1)) & 0x7FF
    out[:, 5] = ((r[6] << 10) | (r[7] << 2) | (r[8] >> 6)) & 0x7FF
    out[:, 6] = ((r[8] << 5) | (r[9] >> 3)) & 0x7FF
    out[:, 7] = ((r[9] << 8) | r[10]) & 0x7FF
    return out.reshape(shape)


def blank_byte_ranges(image: np.ndarray, ranges) -> np.ndarray:
    """Set to no-reading every pixel with any bit in the given (start, end) byte ranges of the packed frame.

    Pixels straddling the edge of a lost packet hold a mix of real and filler bits; they must not pass
    for readings.
    """
    flat = image.reshape(-1)
    for start, end in ranges:
        first, last = (8 * start) // 11, (8 * end - 1) // 11
        flat[first:last + 1] = NO_READING_RAW
    return image


def pack_11bit(image: np.ndarray) -> bytes:
    """uint16 image of 11-bit values (pixel count a multiple of 8) -> packed bytes, MSB first."""
    img = np.asarray(image)
    if img.size % 8:
        raise ValueError(f"pixel count {img.size} is not a multiple of 8")
    if img.size and (img.min() < 0 or img.max() > 0x7FF):
        raise ValueError("depth values must be 11-bit (0..2047)")
    p = img.reshape(-1, 8).T.astype(np.uint16)
    out = np.empty((p.shape[1], 11), dtype=np.uint16)
    out[:, 0] = p[0] >> 3
    out[:, 1] = ((p[0] & 0x7) << 5) | (p[1] >> 6)
    out[:, 2] = ((p[1] & 0x3F) << 2) | (p[2] >> 9)
    out[:, 3] = (p[2] >> 1) & 0xFF
    out[:, 4] = ((p[2] & 0x1) << 7) | (p[3] >> 4)
    out[:, 5] = ((p[3] & 0xF) << 4) | (p[4] >> 7)
    out[:, 6] = ((p[4] & 0x7F) << 1) | (p[5] >> 10)
    out[:, 7] = (p[5] >> 2) & 0xFF
    out[:, 8] = ((p[5] & 0x3) << 6) | (p[6] >> 5)
    out[:, 9] = ((p[6] & 0x1F) << 3) | (p[7] >> 8)
    out[:, 10] = p[7] & 0xFF
    return out.astype(np.uint8).tobytes()


assert DEPTH_FRAME_BYTES == DEPTH_WIDTH * DEPTH_HEIGHT * 11 // 8
