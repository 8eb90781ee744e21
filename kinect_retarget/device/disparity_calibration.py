"""Raw 11-bit disparity -> millimetres, from the calibration the device reports about itself.

The formula is libfreenect's (registration.c), evaluated once into a 2048-entry table:
    x  = (raw - 4*const_shift)/4 - 0.375
    m  = x * reference_pixel_size                       (mm on the reference plane)
    mm = 10 * (m*reference_distance / (dcmos_emitter_dist - m) + reference_distance)
Units as the device reports them: reference distance and pixel size in mm, emitter distance in cm (the
factor 10 reconciles them). Raw 2047 and results outside (0, 10000] mm become 0, meaning "no reading".
"""
from __future__ import annotations

import struct
from dataclasses import asdict, dataclass

import numpy as np

from .depth_unpack import NO_READING_RAW
from .errors import ProtocolError

MAX_MM = 10_000
FIXED_PARAMS_OFFSET = 94          # 4 little-endian floats inside the OP_FIXED_PARAMS reply payload


@dataclass(frozen=True)
class Calibration:
    const_shift: float = 200.0
    reference_distance: float = 120.0        # mm
    reference_pixel_size: float = 0.1052     # mm
    dcmos_emitter_dist: float = 7.5          # cm
    dcmos_rcmos_dist: float = 2.4            # cm (libfreenect forces OpenNI's 2.4)
    source: str = "typical values"           # "device" when read from the Kinect

    @property
    def focal_length_px(self) -> float:
        """Depth focal length at 640x480: the zero plane's pixel size is for the 1280-wide sensor."""
        return self.reference_distance / (2.0 * self.reference_pixel_size)

    def as_dict(self) -> dict:
        return asdict(self)

    def raw_to_mm_table(self) -> np.ndarray:
        """(2048,) uint16 lookup table: raw value -> millimetres (0 = no reading)."""
        raw = np.arange(2048, dtype=np.float64)
        x = (raw - 4.0 * self.const_shift) / 4.0 - 0.375
        m = x * self.reference_pixel_size
        with np.errstate(divide="ignore", invalid="ignore"):
            mm = 10.0 * (m * self.reference_distance / (self.dcmos_emitter_dist - m) + self.reference_distance)
        valid = np.isfinite(mm) & (mm > 0) & (mm <= MAX_MM)
        table = np.where(valid, np.floor(np.where(valid, mm, 0)), 0).astype(np.uint16)
        table[NO_READING_RAW] = 0
        return table

    def to_mm(self, raw: np.ndarray, table: np.ndarray | None = None) -> np.ndarray:
        """Raw 11-bit image -> uint16 millimetres (0 = no reading)."""
        lut = self.raw_to_mm_table() if table is None else table
        return lut[np.minimum(raw, NO_READING_RAW)]


def parse_fixed_params(payload: bytes) -> tuple[float, float, float, float]:
    """(dcmos_emitter_dist, dcmos_rcmos_dist, reference_distance, reference_pixel_size) from an 0x04 reply."""
    end = FIXED_PARAMS_OFFSET + 16
    if len(payload) < end:
        raise ProtocolError(f"fixed-parameters reply has {len(payload)} bytes, needs at least {end}")
    values = struct.unpack_from("<4f", payload, FIXED_PARAMS_OFFSET)
    if not all(np.isfinite(values)) or values[0] <= 0 or values[2] <= 0 or values[3] <= 0:
        raise ProtocolError(f"fixed parameters out of range: {values}")
    return values


def parse_const_shift(payload: bytes) -> int:
    if len(payload) < 4:
        raise ProtocolError(f"const-shift reply has {len(payload)} bytes, expected 4")
    return struct.unpack_from("<H", payload, 2)[0]


def calibration_from_replies(fixed_payload: bytes, shift_payload: bytes) -> Calibration:
    emitter, _rcmos, ref_dist, ref_pix = parse_fixed_params(fixed_payload)
    return Calibration(const_shift=float(parse_const_shift(shift_payload)), reference_distance=ref_dist,
                       reference_pixel_size=ref_pix, dcmos_emitter_dist=emitter, dcmos_rcmos_dist=2.4,
                       source="device")


def mm_to_raw(mm: np.ndarray, calibration: Calibration = Calibration()) -> np.ndarray:
    """Inverse of the table (nearest raw value), for synthesising depth images: 0 mm -> 2047."""
    table = calibration.raw_to_mm_table().astype(np.float64)
    valid = np.nonzero(table > 0)[0]              # table is increasing over its valid range
    mm = np.asarray(mm, dtype=np.float64)
    idx = np.clip(np.searchsorted(table[valid], mm), 0, valid.size - 1)
    raw = valid[idx].astype(np.uint16)
    return np.where(mm > 0, raw, NO_READING_RAW).astype(np.uint16)
