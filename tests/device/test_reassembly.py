import numpy as np
import pytest

from kinect_retarget.device.depth_unpack import unpack_11bit
from kinect_retarget.sim.emulated_stream import packets_for_frames
from kinect_retarget.device.protocol import DEPTH_PACKETS_PER_FRAME as PPF, DEPTH_PAYLOAD, TICKS_PER_FRAME
from kinect_retarget.device.reassembly import FrameAssembler


@pytest.fixture(scope="module")
def three_frames(real_depth):
    images = real_depth[:3]
    return images, packets_for_frames(images, 3, first_seq=200, first_timestamp=2**32 - 3_000_000)


def test_clean_stream_is_bit_exact_across_sequence_and_timestamp_wrap(three_frames):
    images, packets = three_frames            # 726 packets: seq wraps 255->0 twice, timestamp wraps once
    frames = FrameAssembler().feed(packets)
    assert len(frames) == 3
    for img, f in zip(images, frames):
        np.testing.assert_array_equal(unpack_11bit(f.packed), img)
        assert f.lost_packets == 0
    stamps = [f.timestamp for f in frames]
    assert [(b - a) & 0xFFFFFFFF for a, b in zip(stamps, stamps[1:])] == [TICKS_PER_FRAME] * 2


def test_stream_joined_mid_frame_waits_for_start_of_frame(three_frames):
    images, packets = three_frames
    asm = FrameAssembler()
    frames = asm.feed(packets[100:])
    assert len(frames) == 2
    np.testing.assert_array_equal(unpack_11bit(frames[0].packed), images[1])


@pytest.mark.parametrize("lost", [1, 3, 5])
def test_small_gap_is_skipped_and_frame_delivered(three_frames, lost):
    images, packets = three_frames
    first = 50
    kept = packets[:first] + packets[first + lost:]
    asm = FrameAssembler()
    frames = asm.feed(kept)
    assert len(frames) == 3 and frames[0].lost_packets == lost
    raw = unpack_11bit(frames[0].packed)
    # Pixels of the missing payload read "no reading"; everything else is exact.
    k = np.arange(480 * 640)
    first_byte, last_byte = (11 * k) >> 3, (11 * k + 10) >> 3
    lo, hi = first * DEPTH_PAYLOAD, (first + lost) * DEPTH_PAYLOAD
    inside = ((first_byte >= lo) & (last_byte < hi)).reshape(480, 640)
    outside = ((last_byte < lo) | (first_byte >= hi)).reshape(480, 640)
    assert inside.sum() > 1000 * lost
    assert (raw[inside] == 2047).all()
    np.testing.assert_array_equal(raw[outside], images[0][outside])
    assert asm.stats.packets_lost == lost


def test_gap_above_threshold_drops_the_frame_and_resyncs(three_frames):
    images, packets = three_frames
    asm = FrameAssembler()
    frames = asm.feed(packets[:50] + packets[56:])          # 6 consecutive packets lost
    assert len(frames) == 2
    np.testing.assert_array_equal(unpack_11bit(frames[0].packed), images[1])
    assert asm.stats.frames_dropped == 1 and asm.stats.resyncs == 1


def test_many_small_gaps_add_up_and_drop_the_frame(three_frames):
    images, packets = three_frames
    kept = [p for i, p in enumerate(packets) if i not in (10, 40, 70, 100, 130, 160)]   # 6 singles in frame 0
    frames = FrameAssembler().feed(kept)
    assert [f.timestamp for f in frames] == [f.timestamp for f in FrameAssembler().feed(packets)][1:]


def test_gap_across_frame_boundary_keeps_both_frames_and_the_timestamp(three_frames):
    images, packets = three_frames
    clean = FrameAssembler().feed(packets)
    asm = FrameAssembler()
    frames = asm.feed(packets[:PPF - 2] + packets[PPF + 1:])   # last 2 of frame 0 and SOF of frame 1 lost
    assert [f.lost_packets for f in frames] == [2, 1, 0]
    assert [f.timestamp for f in frames] == [f.timestamp for f in clean]   # frame 1's estimated exactly
    np.testing.assert_array_equal(unpack_11bit(frames[2].packed), images[2])
    assert asm.stats.packets_lost == 3 and asm.stats.frames_dropped == 0


def test_lost_start_of_frame_after_a_complete_frame(three_frames):
    images, packets = three_frames
    frames = FrameAssembler().feed(packets[:PPF] + packets[PPF + 3:])
    assert [f.lost_packets for f in frames] == [0, 3, 0]
    assert (frames[1].timestamp - frames[0].timestamp) & 0xFFFFFFFF == TICKS_PER_FRAME


def test_failed_slots_truncated_and_foreign_packets(three_frames):
    images, packets = three_frames
    damaged = list(packets)
    damaged[30] = None                                       # reported failed by the USB stack
    damaged[60] = packets[60][:500]                          # truncated
    damaged.insert(90, b"junk that is not a packet")
    damaged.insert(31, b"")                                  # empty microframe: normal
    asm = FrameAssembler()
    frames = asm.feed(damaged)
    assert len(frames) == 3
    assert frames[0].lost_packets == 2                       # the failed slot and the truncated one
    assert (asm.stats.packets_error, asm.stats.packets_damaged, asm.stats.packets_bad) == (1, 1, 1)
    raw = unpack_11bit(frames[0].packed)
    before_loss = 30 * DEPTH_PAYLOAD * 8 // 11               # pixels before the first failed slot
    np.testing.assert_array_equal(raw.reshape(-1)[:before_loss], images[0].reshape(-1)[:before_loss])
    np.testing.assert_array_equal(unpack_11bit(frames[1].packed), images[1])


def test_out_of_place_flag_resyncs(three_frames):
    images, packets = three_frames
    bad = bytearray(packets[20])
    bad[3] = 0x75                                            # EOF flag in the middle of a frame
    asm = FrameAssembler()
    frames = asm.feed(packets[:20] + [bytes(bad)] + packets[21:])
    assert len(frames) == 2 and asm.stats.resyncs == 1


def test_resync_picks_up_a_frame_whose_start_was_lost(three_frames):
    images, packets = three_frames
    clean = FrameAssembler().feed(packets)
    asm = FrameAssembler()
    # frame 0 loses 6 packets (dropped, resync); then frame 1 loses its start-of-frame and one more packet
    frames = asm.feed(packets[:50] + packets[56:PPF] + packets[PPF + 2:])
    assert [f.lost_packets for f in frames] == [2, 0]
    assert [f.timestamp for f in frames] == [f.timestamp for f in clean[1:]]
    assert asm.stats.packets_lost == 8 and asm.stats.frames_dropped == 1
    np.testing.assert_array_equal(unpack_11bit(frames[1].packed), images[2])
