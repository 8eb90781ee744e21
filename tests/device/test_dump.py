import struct

import numpy as np
import pytest

from kinect_retarget.device.depth_unpack import unpack_11bit
from kinect_retarget.device.dump import DumpWriter, read_dump, replay_dump
from kinect_retarget.sim.emulated_stream import packets_for_frames
from kinect_retarget.device.errors import DumpError


@pytest.fixture
def dump_path(tmp_path, real_depth):
    packets = packets_for_frames(real_depth[:3], 3, first_seq=17)
    packets[100] = None                                    # a lost packet
    packets.insert(50, b"")                                # an empty microframe: not recorded
    path = tmp_path / "take.dump"
    with DumpWriter(path) as writer:
        for i in range(0, len(packets), 32):
            writer.write_packets(packets[i:i + 32])
    return path, packets


def test_format_is_length_prefixed_records(dump_path):
    path, packets = dump_path
    data = path.read_bytes()
    first = packets[0]
    assert data[:4] == struct.pack("<I", len(first)) and data[4:4 + len(first)] == first
    assert len(data) == sum(4 + len(p) for p in packets if p is not None and len(p)) + 4   # +4: the lost one
    read = list(read_dump(path))
    assert read == [p for p in packets if p is None or len(p)]


def test_replay_goes_through_the_same_reassembly(dump_path, real_depth):
    path, _ = dump_path
    frames, assembler, error = replay_dump(path)
    assert error is None and len(frames) == 3
    assert frames[0].lost_packets == 1 and assembler.stats.packets_error == 1
    for img, f in zip(real_depth[1:3], frames[1:]):
        np.testing.assert_array_equal(unpack_11bit(f.packed), img)


def test_truncated_dump_keeps_frames_before_the_damage(dump_path, real_depth, tmp_path):
    path, _ = dump_path
    data = path.read_bytes()
    cut = tmp_path / "cut.dump"
    cut.write_bytes(data[:len(data) - 1000])               # the last packet of frame 3 is cut short
    frames, _, error = replay_dump(cut)
    assert len(frames) == 2
    assert isinstance(error, DumpError) and "cut.dump" in str(error) and "record" in str(error)
    np.testing.assert_array_equal(unpack_11bit(frames[1].packed), real_depth[1])


def test_garbage_file_is_named(tmp_path):
    junk = tmp_path / "notes.txt"
    junk.write_bytes(b"hello, this is not a dump at all")
    with pytest.raises(DumpError, match="notes.txt.*record 0"):
        list(read_dump(junk))
    with pytest.raises(DumpError, match="no such dump"):
        replay_dump(tmp_path / "missing.dump")
