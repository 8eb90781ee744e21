"""End to end: DepthStream (the real driver code) against the emulated Kinect."""
import queue
import time

import numpy as np

from kinect_retarget.device.emulated import EmulatedKinect
from kinect_retarget.device.emulated_stream import Faults, VirtualClock
from kinect_retarget.device import protocol as P
from kinect_retarget.device.protocol import TICKS_PER_FRAME
from kinect_retarget.device.stream import STOPPED, STREAMING, UNPLUGGED, DepthStream


def _drain(stream, until, frames=None, states=None):
    """Collect frames (and the states seen) until until() is true or 20 s pass."""
    frames = [] if frames is None else frames
    deadline = time.monotonic() + 20
    while not until(frames) and time.monotonic() < deadline:
        if states is not None:
            states.add(stream.status.state)
        try:
            frames.append(stream.frames.get(timeout=0.02))
        except queue.Empty:
            pass
    return frames


def test_three_seconds_real_time_every_frame_bit_exact(real_depth):
    emu = EmulatedKinect(real_depth)
    stream = DepthStream(emu, queue_size=16).start()
    frames = _drain(stream, lambda f: len(f) >= 90)
    status = stream.status
    assert stream.stop()
    assert len(frames) == 90, stream.status.message
    assert [f.index for f in frames] == list(range(90))
    assert emu.expected_frame(frames[0].timestamp) == (0, 0)             # from the stream's first frame
    steps = {(b.timestamp - a.timestamp) & 0xFFFFFFFF for a, b in zip(frames, frames[1:])}
    assert steps == {TICKS_PER_FRAME}                                     # no frame missing
    lut = frames[0].calibration.raw_to_mm_table()
    for f in frames:
        np.testing.assert_array_equal(f.raw, emu.expected_raw(f.timestamp))
        np.testing.assert_array_equal(f.mm, lut[f.raw])
        assert f.lost_packets == 0
    assert (status.frames_dropped, status.packets_lost, status.queue_overflows) == (0, 0, 0)
    assert emu.last_pump.overrun_packets == 0
    assert stream.status.state == STOPPED


def test_injected_loss_drops_exactly_the_frames_with_more_than_five_lost(real_depth):
    clock = VirtualClock()
    faults = Faults(loss_rate=0.01, bursts=[(5, 100, 6), (12, 0, 3), (30, 240, 4)], truncate=[(20, 50, 300)],
                    seed=7)
    emu = EmulatedKinect(real_depth, faults=faults, clock=clock)
    stream = DepthStream(emu, queue_size=1000).start()
    frames = _drain(stream, lambda f: len(f) >= 40 and emu.expected_frame(f[-1].timestamp)[1] >= 45)
    stream.stop()
    got = {emu.expected_frame(f.timestamp)[1]: f for f in frames}
    last = max(got)
    lost = {frame: n for (_, frame), n in emu.last_pump.faulted.items() if frame <= last}
    expected = {k for k in range(last + 1) if lost.get(k, 0) <= 5}
    assert set(got) == expected
    assert 5 not in got and lost[5] >= 6
    assert lost[12] >= 3 and lost[20] >= 1 and lost[30] >= 2 and lost[31] >= 2
    assert {20, 30, 31} <= set(got)                   # damaged ends / starts of frames still delivered
    assert sum(0 < lost.get(k, 0) for k in expected) >= 10   # random loss hit many delivered frames
    assert len(set(range(last + 1)) - expected) >= 2           # and pushed some frames over the limit
    for k, f in got.items():
        assert f.lost_packets == lost.get(k, 0)
        truth = emu.images[k % len(emu.images)]
        intact = f.raw != 2047
        np.testing.assert_array_equal(f.raw[intact], truth[intact])
        if f.lost_packets == 0:
            np.testing.assert_array_equal(f.raw, truth)
    assert stream.status.frames_dropped == len(set(range(last + 1)) - expected)


def test_unplug_keeps_frames_and_streaming_resumes_after_replug(real_depth):
    emu = EmulatedKinect(real_depth[:3], faults=Faults(unplug_at=0.5, replug_at=0.9))
    stream = DepthStream(emu, queue_size=200, reconnect_interval=0.05).start()
    states, messages = set(), set()
    frames = []
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        status = stream.status
        states.add(status.state)
        messages.add(status.message)
        try:
            frames.append(stream.frames.get(timeout=0.02))
        except queue.Empty:
            pass
        if len(emu.streams) == 2 and frames and emu.expected_frame(frames[-1].timestamp)[0] == 1 \
                and len(frames) > 20:
            break
    stream.stop()
    by_stream = [emu.expected_frame(f.timestamp)[0] for f in frames]
    assert UNPLUGGED in states and STREAMING in states
    assert any("unplugged" in m and "frames kept" in m for m in messages)
    assert by_stream.count(0) >= 12                # about 15 frames before the unplug, all kept
    assert by_stream[-1] == 1 and stream.status.reconnects == 1
    assert by_stream == sorted(by_stream)
    for f in frames:
        np.testing.assert_array_equal(f.raw, emu.expected_raw(f.timestamp))


def test_stop_ends_the_thread_and_releases_the_device(real_depth):
    emu = EmulatedKinect(real_depth[:2])
    stream = DepthStream(emu).start()
    _drain(stream, lambda f: len(f) >= 3)
    assert stream.poll_timeout <= 0.02             # the loop checks for stop at least every 20 ms
    assert stream.stop(timeout=2.0)
    assert not stream.running and stream.status.state == STOPPED
    assert emu.depth_stream is None                # the driver sent the stop sequence
    writes = [(reg, value) for reg, value, _ in emu.register_log]
    assert writes == list(P.DEPTH_START_SEQUENCE + P.DEPTH_STOP_SEQUENCE)
    assert all(queued for _, _, queued in emu.register_log[:-1])   # iso transfers queued before the start


def test_latest_frame_for_a_live_preview(real_depth):
    from kinect_retarget.device import depth_preview
    emu = EmulatedKinect(real_depth[:3])
    with DepthStream(emu, queue_size=4) as stream:
        assert stream.latest_frame() is None or stream.status.frames > 0
        deadline = time.monotonic() + 20
        while stream.status.frames < 4 and time.monotonic() < deadline:   # let a few frames pile up
            time.sleep(0.01)
        newest = stream.latest_frame()
        assert newest is not None and stream.frames.empty()
        assert newest.index >= 3
        assert depth_preview(newest.mm).shape == (120, 160)
    assert not stream.running


def test_waiting_for_a_device_that_is_not_there(real_depth):
    emu = EmulatedKinect(real_depth[:1])
    emu.unplug()
    stream = DepthStream(emu, reconnect_interval=0.02).start()
    deadline = time.monotonic() + 10
    while "no Kinect found" not in stream.status.message and time.monotonic() < deadline:
        time.sleep(0.01)
    assert "no Kinect found" in stream.status.message
    emu.replug()
    assert len(_drain(stream, lambda f: len(f) >= 2)) >= 2
    stream.stop()
