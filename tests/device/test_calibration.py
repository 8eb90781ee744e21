import struct

import numpy as np
import pytest

from kinect_retarget.device.disparity_calibration import (Calibration, calibration_from_replies, mm_to_raw,
                                                parse_fixed_params)
from kinect_retarget.device.errors import ProtocolError


def _published(raw, c: Calibration):
    """libfreenect's freenect_raw_to_mm, written out for one value."""
    fixed_ref_x = (raw - 4 * c.const_shift) / 4 - 0.375
    metric = fixed_ref_x * c.reference_pixel_size
    return 10 * (metric * c.reference_distance / (c.dcmos_emitter_dist - metric) + c.reference_distance)


@pytest.mark.parametrize("cal", [Calibration(), Calibration(const_shift=190, reference_distance=118.5,
                                                            reference_pixel_size=0.104, dcmos_emitter_dist=7.6)])
def test_table_matches_the_published_formula(cal):
    table = cal.raw_to_mm_table()
    for raw in range(0, 2047):
        mm = _published(raw, cal)
        expect = int(np.floor(mm)) if 0 < mm <= 10_000 else 0
        assert table[raw] == expect, raw
    assert table[2047] == 0


def test_known_points_with_typical_parameters():
    table = Calibration().raw_to_mm_table()
    assert table[600] == 703 and table[800] == 1193 and table[1000] == 3948


def test_focal_length():
    assert Calibration().focal_length_px == pytest.approx(570.34, abs=0.01)


def test_real_frame_to_mm(real_depth):
    raw = real_depth[0]
    mm = Calibration().to_mm(raw)
    assert mm.dtype == np.uint16
    assert (mm[raw == 2047] == 0).all()
    valid = mm[raw < 2047]
    # The person stands about 1-1.3 m away, the office behind: readings in 0.5-10 m.
    assert 500 < np.median(valid) < 10_000


def test_replies_to_calibration():
    fixed = bytearray(322)
    struct.pack_into("<4f", fixed, 94, 7.5, 2.3, 120.0, 0.1042)
    cal = calibration_from_replies(bytes(fixed), b"\0\0" + struct.pack("<H", 203))
    assert cal.const_shift == 203 and cal.source == "device"
    assert cal.reference_pixel_size == pytest.approx(0.1042) and cal.dcmos_rcmos_dist == 2.4


def test_short_or_absurd_fixed_params_are_errors():
    with pytest.raises(ProtocolError, match="322|110"):
        parse_fixed_params(bytes(50))
    with pytest.raises(ProtocolError, match="range"):
        parse_fixed_params(bytes(322))


def test_mm_to_raw_inverts_the_table():
    cal = Calibration()
    table = cal.raw_to_mm_table()
    raws = np.array([500, 700, 900, 1000])
    np.testing.assert_array_equal(mm_to_raw(table[raws], cal), raws)
    assert mm_to_raw(np.array([0]))[0] == 2047
