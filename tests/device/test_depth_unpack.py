import numpy as np
import pytest

from kinect_retarget.device.depth_unpack import pack_11bit, unpack_11bit


def _reference_pack(values: np.ndarray) -> bytes:
    """Independent packer: write each value's 11 bits MSB first into one long bit string."""
    bits = ((values[:, None].astype(np.uint32) >> np.arange(10, -1, -1)) & 1).astype(np.uint8)
    return np.packbits(bits.reshape(-1)).tobytes()


@pytest.mark.parametrize("offset", range(8))
def test_every_value_at_every_bit_offset(offset):
    # Pixel `offset` of each 8-pixel group starts at bit 11*offset: put all 2048 values there.
    values = np.full((2048, 8), 1234, dtype=np.uint16)
    values[:, offset] = np.arange(2048)
    flat = values.reshape(-1)
    packed = _reference_pack(flat)
    out = unpack_11bit(packed, shape=(2048, 8))
    np.testing.assert_array_equal(out[:, offset], np.arange(2048))
    np.testing.assert_array_equal(out, values)
    assert pack_11bit(values) == packed


def test_real_frame_round_trip(real_depth):
    img = real_depth[0]
    packed = pack_11bit(img)
    assert len(packed) == 422_400
    assert packed == _reference_pack(img.reshape(-1))
    np.testing.assert_array_equal(unpack_11bit(packed), img)


def test_all_ones_is_no_reading():
    assert (unpack_11bit(b"\xff" * 422_400) == 2047).all()


def test_wrong_length_is_a_clear_error():
    with pytest.raises(ValueError, match="422400"):
        unpack_11bit(b"\0" * 1000)
    with pytest.raises(ValueError, match="11-bit"):
        pack_11bit(np.full(8, 4096))


def test_blank_byte_ranges_covers_straddling_pixels(real_depth):
    from kinect_retarget.device.depth_unpack import blank_byte_ranges
    img = real_depth[1]
    packed = bytearray(pack_11bit(img))
    packed[1000:2000] = b"\xff" * 1000                 # as the assembler leaves a lost region
    raw = blank_byte_ranges(unpack_11bit(bytes(packed)), [(1000, 2000)])
    k = np.arange(img.size)
    touched = ((11 * k + 10) >> 3 >= 1000) & ((11 * k) >> 3 < 2000)
    assert (raw.reshape(-1)[touched] == 2047).all()
    np.testing.assert_array_equal(raw.reshape(-1)[~touched], img.reshape(-1)[~touched])
