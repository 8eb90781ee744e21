"""End to end: DepthStream (the real driver code) against the emulated Kinect."""
import queue
import time

import numpy as np

from kinect_retarget.sim.emulated_kinect import EmulatedKinect
from kinect_retarget.sim.emulated_stream import Faults, VirtualClock
from kinect_retarget.device import protocol as P
from kinect_retarget.device.protocol import TICKS_PER_FRAME
from kinect_retarget.device.depth_stream import STOPPED, STREAMING, UNPLUGGED, DepthStream


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


def test_ninety_frames_every_frame_bit_exact(real_depth):
    # the virtual clock makes "no packet overran the armed transfers" independent of machine load; whether
    # the thread keeps up in real time is measured by benchmarks/bench_depth_stream.py
    emu = EmulatedKinect(real_depth, clock=VirtualClock())
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
    assert emu.lib.overrun_packets == 0
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
    lost = {frame: n for (_, frame), n in emu.lib.faulted.items() if frame <= last}
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


def _frames_before_unplug(unplug_at: float) -> int:
    """Frames of the first stream whose last packet is on the wire before `unplug_at` seconds of device time
    (the test's expectation, from the wire timing rather than from the code under test). Pick `unplug_at`
    away from a frame's end: packets reach the host a 4 ms transfer at a time."""
    from kinect_retarget.sim.emulated_stream import packet_due_time
    return sum(packet_due_time((f + 1) * P.DEPTH_PACKETS_PER_FRAME - 1) < unplug_at for f in range(100))


def test_unplug_keeps_frames_and_streaming_resumes_after_replug(real_depth):
    # device time is a virtual clock that only the emulator (and this test) moves, so what arrives before
    # the unplug does not depend on how loaded the machine is
    clock = VirtualClock()
    emu = EmulatedKinect(real_depth[:3], faults=Faults(unplug_at=0.51, replug_at=0.9), clock=clock)
    stream = DepthStream(emu, queue_size=200, reconnect_interval=0.05).start()
    states, messages = set(), set()

    def watch(frames):
        status = stream.status
        states.add(status.state)
        messages.add(status.message)
        return status.state == UNPLUGGED

    before = _drain(stream, watch)                 # the thread holds device time still while unplugged
    before = _drain(stream, lambda f: stream.frames.empty(), before)   # everything queued before the unplug
    assert UNPLUGGED in states and STREAMING in states
    assert any("unplugged" in m and "frames kept" in m for m in messages)
    clock.sleep(0.5)                               # past replug_at: the Kinect is back
    frames = _drain(stream, lambda f: len(f) > 20 and emu.expected_frame(f[-1].timestamp)[0] == 1,
                    list(before))
    stream.stop()
    by_stream = [emu.expected_frame(f.timestamp)[0] for f in frames]
    expected_before = _frames_before_unplug(0.51)
    assert expected_before >= 12                   # about 15 frames before the unplug,
    assert [emu.expected_frame(f.timestamp) for f in before] == [(0, k) for k in range(expected_before)]
    assert by_stream.count(0) == expected_before   # all kept
    assert len(emu.streams) == 2 and by_stream[-1] == 1 and stream.status.reconnects == 1
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
    stream = DepthStream(emu, queue_size=4)
    assert stream.latest_frame() is None           # nothing arrived yet
    with stream:
        deadline = time.monotonic() + 20
        while stream.status.frames < 6 and time.monotonic() < deadline:   # let frames pile up past the queue
            time.sleep(0.01)
    assert not stream.running                      # stopped, so no frame can land between the checks below
    delivered = stream.status.frames
    newest = stream.latest_frame()
    assert newest is not None and stream.frames.empty()
    assert delivered >= 6 and newest.index == delivered - 1
    assert depth_preview(newest.mm).shape == (120, 160)


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
