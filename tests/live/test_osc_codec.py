import struct

import pytest

from kinect_retarget.sources.osc_codec import OscError, encode_bundle, encode_message, parse_packet


def test_message_round_trip():
    pkt = encode_message("/Left_Hand", 0.25, -1.5, 2.0)
    assert parse_packet(pkt) == [("/Left_Hand", [0.25, -1.5, 2.0])]


def test_bundle_flattens_in_order():
    msgs = [encode_message("/Head", 1.0, 2.0, 3.0), encode_message("/NI_mate_sync", "skel")]
    assert parse_packet(encode_bundle(msgs)) == [("/Head", [1.0, 2.0, 3.0]), ("/NI_mate_sync", ["skel"])]


def test_int_and_double_arguments_are_numbers():
    pkt = b"/Head\x00\x00\x00,idf\x00\x00\x00\x00" + struct.pack(">i", 3) + struct.pack(">d", 0.5) + \
        struct.pack(">f", 1.5)
    assert parse_packet(pkt) == [("/Head", [3, 0.5, 1.5])]


@pytest.mark.parametrize("garbage, why", [
    (b"", "multiple of 4"),
    (b"abc", "multiple of 4"),
    (b"Head\x00\x00\x00\x00", "does not start with '/'"),
    (b"/Head\x00\x00\x00,fff\x00\x00\x00\x00" + b"\x00" * 4, "ends inside"),
    (b"/Head\x00\x00\x00,fbf\x00\x00\x00\x00" + b"\x00" * 12, "unsupported OSC argument type"),
    (b"/Hea", "unterminated"),
    (b"#bundle\x00" + b"\x00" * 8 + struct.pack(">i", 400) + b"\x00" * 4, "overruns"),
    (b"/\xff\xfe\x00", "non-ASCII"),
])
def test_garbage_is_rejected_with_a_reason(garbage, why):
    with pytest.raises(OscError, match=why):
        parse_packet(garbage)
