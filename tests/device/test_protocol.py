import struct

import numpy as np
import pytest

from kinect_retarget.device import protocol as P
from kinect_retarget.device.errors import ProtocolError


def test_command_header_layout():
    msg = P.write_register_command(0x105, 0x00, tag=7)
    assert msg[:2] == b"GM"
    assert struct.unpack("<HHH", msg[2:8]) == (2, P.OP_WRITE_REGISTER, 7)   # 2 words of payload
    assert struct.unpack("<HH", msg[8:]) == (0x105, 0)


def test_command_round_trip_through_parse_header():
    msg = P.build_command(P.OP_ALGORITHM_PARAMS, 0xFFFF, P.words(0, 0, 1, 30, 0))
    hdr = P.parse_header(msg)
    assert (hdr.magic, hdr.words, hdr.opcode, hdr.tag) == (b"GM", 5, 0x16, 0xFFFF)


def test_odd_or_oversized_payload_is_refused():
    with pytest.raises(ValueError):
        P.build_command(2, 0, b"\x01")
    with pytest.raises(ValueError):
        P.build_command(2, 0, bytes(P.CMD_MAX_PAYLOAD + 2))


def _reply(opcode, tag, payload, magic=b"RB", words=None):
    return struct.pack("<2sHHH", magic, len(payload) // 2 if words is None else words, opcode, tag) + payload


def test_reply_validation_accepts_a_good_reply():
    assert P.parse_reply(_reply(2, 5, b"\x06\x00\x02\x00"), 2, 5) == b"\x06\x00\x02\x00"


@pytest.mark.parametrize("reply, why", [
    (_reply(2, 5, b"\0\0", magic=b"GM"), "magic"),
    (_reply(3, 5, b"\0\0"), "opcode"),
    (_reply(2, 6, b"\0\0"), "tag"),
    (_reply(2, 5, b"\0\0", words=2), "announces"),
    (b"RB\x01", "shorter"),
])
def test_reply_validation_rejects(reply, why):
    with pytest.raises(ProtocolError, match=why):
        P.parse_reply(reply, 2, 5)


def test_start_and_stop_register_sequences():
    assert P.DEPTH_START_SEQUENCE == ((0x105, 0), (0x06, 0), (0x12, 3), (0x13, 1), (0x14, 0x1E),
                                      (0x06, 2), (0x17, 0))
    assert P.DEPTH_STOP_SEQUENCE == ((0x06, 0),)


def test_packet_geometry():
    assert P.DEPTH_FRAME_BYTES == 422_400
    assert P.DEPTH_PACKETS_PER_FRAME == 242
    assert P.DEPTH_LAST_PAYLOAD == 1132
    assert P.TICKS_PER_FRAME == 2_000_000


def test_packet_header_parse_matches_the_wire_layout():
    raw = bytes([0x52, 0x42, 0x00, 0x75, 0x00, 0xFE, 0x04, 0x78]) + (0xDEADBEEF).to_bytes(4, "little")
    hdr = P.parse_packet_header(raw)
    assert (hdr.flag, hdr.seq, hdr.length, hdr.timestamp) == (0x75, 0xFE, 1144, 0xDEADBEEF)
    assert P.build_packet_header(0x75, 0xFE, 1144, 0xDEADBEEF) == raw


def test_packet_header_rejects_short_or_foreign_packets():
    assert P.parse_packet_header(b"RB\0q") is None
    assert P.parse_packet_header(b"XX" + bytes(10)) is None


def test_models():
    assert P.camera_model(0x02AE, 267) == "Xbox 360 Kinect (1414)"
    assert P.camera_model(0x02AE, 0x110) == "Xbox 360 Kinect (1473)"
    assert P.camera_model(0x02BF, 0x100) == "Kinect for Windows"
    assert P.is_model_1414(0x02AE, 267) and not P.is_model_1414(0x02BF, 267)


def test_device_clock_wraps_at_2_to_the_32():
    top = P.TIMESTAMP_WRAP - 1                          # the counter's last reading before it wraps to 0
    assert P.wrap_ticks(top) == top and P.wrap_ticks(top + 1) == 0 and P.wrap_ticks(-1) == top
    assert P.advance_ticks(top, 1) == 0
    assert P.advance_ticks(top - P.TICKS_PER_FRAME + 1, P.TICKS_PER_FRAME) == 0
    assert P.advance_ticks(top - 1_000_000, P.TICKS_PER_FRAME) == P.TICKS_PER_FRAME - 1_000_001
    assert P.ticks_between(top, 0) == 1 and P.ticks_between(0, top) == top
    assert P.ticks_between(top - 1_000_000, P.advance_ticks(top - 1_000_000, P.TICKS_PER_FRAME)) == P.TICKS_PER_FRAME
    # the same values the inline `& 0xFFFFFFFF` gave, for ints on both sides of the boundary and for arrays
    for t in (-P.TIMESTAMP_WRAP - 5, -1, 0, 1, top, top + 1, top + P.TICKS_PER_FRAME, 3 * P.TIMESTAMP_WRAP + 7):
        assert P.wrap_ticks(t) == t & 0xFFFFFFFF
    earlier = np.array([top - 5, top, 0, 17], dtype=np.int64)
    later = np.array([2, 0, top, 17], dtype=np.int64)
    assert P.ticks_between(earlier, later).tolist() == [8, 1, top, 0]
    assert P.advance_ticks(earlier, P.TICKS_PER_FRAME).tolist() == ((earlier + P.TICKS_PER_FRAME) & 0xFFFFFFFF).tolist()


def test_packet_header_carries_the_wrapped_stamp():
    header = P.build_packet_header(P.FLAG_DEPTH_SOF, 3, 1760, P.TIMESTAMP_WRAP + 42)
    assert P.parse_packet_header(header + bytes(4)).timestamp == 42
