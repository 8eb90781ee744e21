import os
import socket
import time

import numpy as np
import pytest

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, KINECT_V2, NOT_TRACKED, TRACKED
from kinect_retarget.sources.frame_queue import FrameQueue
from kinect_retarget.sources import OscReceiver, SourceError, TakePlayback, UsbKinectSource, open_source
from kinect_retarget.sources.osc_receiver import FrameAssembler
from kinect_retarget.sources.osc_codec import OscError, encode_bundle, encode_message


def wait_until(cond, timeout=5.0):
    end = time.perf_counter() + timeout
    while time.perf_counter() < end:
        if cond():
            return True
        time.sleep(0.005)
    return cond()


def test_playback_delivers_every_frame_in_order_at_speed(wave_take):
    q = FrameQueue()
    src = TakePlayback(wave_take, speed=20.0)
    src.start(q)
    assert wait_until(lambda: src.status == "finished")
    src.stop()
    frames = q.drain()
    assert len(frames) == wave_take.frame_count
    np.testing.assert_array_equal(np.stack([f.positions for f in frames]), wave_take.positions)
    t = np.array([f.time_s for f in frames])
    np.testing.assert_allclose(t, (wave_take.times - wave_take.times[0]) / 20.0)
    assert not src.alive


def test_playback_loops_until_stopped(wave_take):
    q = FrameQueue(capacity=100000)
    src = TakePlayback(wave_take, speed=50.0, loop=True)
    src.start(q)
    assert wait_until(lambda: src.frames_emitted > 2 * wave_take.frame_count)
    src.stop()
    assert src.status == "stopped" and not src.alive
    frames = q.drain()
    t = np.array([f.time_s for f in frames])
    assert np.all(np.diff(t) > 0), "loop laps must keep time increasing"


def test_playback_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(SourceError, match="does not exist"):
        TakePlayback(tmp_path / "nope.krtake")



def test_playback_shows_the_samples_the_reader_dropped(tmp_path):
    """A take with a few NaN samples plays its good ones, the reader's warning shown as the source's."""
    csv = os.path.join(os.path.dirname(__file__), "..", "data", "kinect_v2", "Ges01_wavehand.csv")
    with open(csv) as fh:
        lines = [fh.readline().rstrip().rstrip(",") for _ in range(20)]
    cells = lines[5].split(",")
    lines[5] = ",".join(c if i == 0 or i % 4 == 0 else "nan" for i, c in enumerate(cells))  # states kept
    path = tmp_path / "some_nan.csv"
    path.write_text("\n".join(lines) + "\n")
    src = TakePlayback(path)
    assert src.take.frame_count == 20
    assert src.warning is not None and "some_nan.csv:6" in src.warning and "NaN" in src.warning

def test_playback_file_vanishing_stops_with_error(wave_take_file):
    src = TakePlayback(wave_take_file, speed=1.0)
    q = FrameQueue()
    src.start(q)
    os.remove(wave_take_file)
    assert wait_until(lambda: src.status == "error", 3.0)
    assert "vanished" in src.error and str(wave_take_file) in src.error
    src.stop()
    assert not src.alive


def test_open_source_specs(wave_take_file):
    assert isinstance(open_source(f"take:{wave_take_file}"), TakePlayback)
    assert isinstance(open_source("osc:9001"), OscReceiver)
    assert isinstance(open_source("usb"), UsbKinectSource) and not open_source("usb").alive   # opens on start
    with pytest.raises(SourceError, match="unknown source"):
        open_source("webcam")
    with pytest.raises(SourceError, match="must be a number"):
        open_source("osc:seven")


# -- OSC ---------------------------------------------------------------------------------------------------
NI_MATE_JOINTS = ["Head", "Neck", "Torso", "Left_Shoulder", "Left_Elbow", "Left_Hand", "Right_Shoulder",
                  "Right_Elbow", "Right_Hand", "Left_Hip", "Left_Knee", "Left_Foot", "Right_Hip",
                  "Right_Knee", "Right_Foot"]


def ni_mate_frame(rng):
    return {name: rng.normal(size=3) for name in NI_MATE_JOINTS}


def test_assembler_maps_ni_mate_names_and_infers_the_root(rng):
    asm = FrameAssembler(KINECT_V2)
    frame = ni_mate_frame(rng)
    for name, xyz in frame.items():
        assert asm.feed("/" + name, list(xyz)) is None
    pos, st = asm.feed("/NI_mate_sync", ["skeleton"])
    k = KINECT_V2.index
    np.testing.assert_allclose(pos[k("HandLeft")], frame["Left_Hand"])
    np.testing.assert_allclose(pos[k("SpineMid")], frame["Torso"])
    assert st[k("HandLeft")] == TRACKED and st[k("WristLeft")] == NOT_TRACKED
    assert st[k("SpineBase")] == INFERRED
    np.testing.assert_allclose(pos[k("SpineBase")], (frame["Left_Hip"] + frame["Right_Hip"]) / 2)


def test_assembler_accepts_sdk_names_and_splits_on_repeat():
    asm = FrameAssembler(KINECT_V1)
    assert asm.feed("/HandLeft", [1, 2, 3]) is None
    assert asm.feed("/Left_Hand_Tip", [1, 2, 3]) is None  # not a v1 joint: ignored, not an error
    assert "/Left_Hand_Tip" in asm.ignored
    pos, st = asm.feed("/HandLeft", [4, 5, 6])  # a repeat starts a new frame
    np.testing.assert_allclose(pos[KINECT_V1.index("HandLeft")], [1, 2, 3])
    pos, st = asm.flush()
    np.testing.assert_allclose(pos[KINECT_V1.index("HandLeft")], [4, 5, 6])


@pytest.mark.parametrize("args", [["1", "2", "3"], [1.0, 2.0], [float("nan"), 0.0, 0.0]])
def test_assembler_rejects_non_numbers(args):
    with pytest.raises(OscError):
        FrameAssembler(KINECT_V2).feed("/Head", args)


def _send(port, packets):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for p in packets:
            s.sendto(p, ("127.0.0.1", port))


@pytest.mark.network   # UDP sockets on localhost
def test_osc_receiver_end_to_end(rng):
    q = FrameQueue()
    src = OscReceiver(port=0)
    src.start(q)
    try:
        assert src._sock.getsockname()[0] == "127.0.0.1"
        frames = [ni_mate_frame(rng) for _ in range(3)]
        for fr in frames:  # plain messages + sync for two frames, a bundle for the third
            _send(src.port, [encode_message("/" + n, *xyz) for n, xyz in fr.items()][:15])
            _send(src.port, [encode_message("/NI_mate_sync", "x")])
        assert wait_until(lambda: len(q) == 3)
        _send(src.port, [encode_bundle([encode_message("/Head", 1.0, 2.0, 3.0)])])
        assert wait_until(lambda: len(q) == 4)
    finally:
        src.stop()
    got = q.drain()
    np.testing.assert_allclose(got[1].positions[KINECT_V2.index("Head")], frames[1]["Head"], rtol=1e-6)
    np.testing.assert_allclose(got[3].positions[KINECT_V2.index("Head")], [1, 2, 3])
    assert not src.alive


@pytest.mark.network   # UDP sockets on localhost
def test_osc_bad_packets_are_counted_and_shown_and_live_goes_on(rng):
    q = FrameQueue()
    src = OscReceiver(port=0)
    src.start(q)
    try:
        _send(src.port, [b"\x13\x37garbage!"])  # not OSC at all
        assert wait_until(lambda: src.bad_packets == 1)
        _send(src.port, [encode_message("/Head", "1", "2", "3")])  # strings: never read as anything else
        assert wait_until(lambda: src.bad_packets == 2)
        assert src.status == "running" and src.error is None and src.alive
        assert "2 bad OSC packet" in src.warning and "packet 2" in src.warning and "127.0.0.1" in src.warning
        _send(src.port, [encode_message("/Head", 1.0, 2.0, 3.0), encode_message("/NI_mate_sync", "x")])
        assert wait_until(lambda: len(q) == 1)  # good frames after the bad ones still arrive
    finally:
        src.stop()
    np.testing.assert_allclose(q.drain()[0].positions[KINECT_V2.index("Head")], [1, 2, 3])
    assert not src.alive


@pytest.mark.network   # UDP sockets on localhost
def test_osc_port_in_use_is_a_clear_error():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as busy:
        busy.bind(("127.0.0.1", 0))
        src = OscReceiver(port=busy.getsockname()[1])
        with pytest.raises(SourceError, match="cannot listen for OSC"):
            src.start(FrameQueue())
    assert not src.alive


@pytest.mark.network   # UDP sockets on localhost
def test_osc_socket_error_on_the_thread_stops_with_error():
    q = FrameQueue()
    src = OscReceiver(port=0)
    src.start(q)
    src._sock.close()  # the socket dies under the thread (network stack gone, handle closed)
    assert wait_until(lambda: src.status == "error")
    assert "socket error" in src.error
    src.stop()
    assert not src.alive


# -- USB -----------------------------------------------------------------------------------------------
def test_usb_opens_the_depth_tracker_by_default_and_says_why_it_cannot(monkeypatch):
    from kinect_retarget.sources import depth_skeletons

    def no_device(**_kwargs):
        raise OSError("no Kinect on the bus")
    monkeypatch.setattr(depth_skeletons, "open_skeleton_producer", no_device)
    src = UsbKinectSource()
    with pytest.raises(SourceError, match="cannot open the device .no Kinect on the bus"):
        src.start(FrameQueue())
    assert not src.alive


class FakeProducer:
    skeleton = KINECT_V1
    rate = 30.0

    def __init__(self, frames, fail_after=None):
        self.frames, self.fail_after, self.n, self.closed = frames, fail_after, 0, False

    def read(self, timeout):
        if self.fail_after is not None and self.n >= self.fail_after:
            raise OSError("device unplugged")
        if self.n >= len(self.frames):
            time.sleep(timeout)
            return None
        self.n += 1
        return self.frames[self.n - 1]

    def close(self):
        self.closed = True


def test_usb_adapter_forwards_producer_frames_and_reports_unplug(rng):
    frames = [(rng.normal(size=(20, 3)), np.full(20, 2, np.uint8), i / 30) for i in range(5)]
    prod = FakeProducer(frames, fail_after=5)
    q = FrameQueue()
    src = UsbKinectSource(factory=lambda: prod)
    src.start(q)
    assert wait_until(lambda: src.status == "error")
    src.stop()
    assert "unplugged" in src.error and prod.closed
    got = q.drain()
    assert len(got) == 5
    np.testing.assert_array_equal(got[4].positions, frames[4][0])


def test_source_rejects_nan_for_tracked_joints(rng):
    pos = rng.normal(size=(20, 3))
    pos[7] = np.nan
    prod = FakeProducer([(pos, np.full(20, 2, np.uint8), 0.0)])
    src = UsbKinectSource(factory=lambda: prod)
    src.start(FrameQueue())
    assert wait_until(lambda: src.status == "error")
    src.stop()
    assert "NaN" in src.error and "HandLeft" in src.error


def test_usb_times_out_without_frames(monkeypatch):
    class Silent(FakeProducer):
        class stream:
            class status:
                message = "Kinect unplugged: waiting for it to come back"

    monkeypatch.setattr(UsbKinectSource, "NO_FRAME_TIMEOUT", 0.3)
    src = UsbKinectSource(factory=lambda: Silent([]))
    src.start(FrameQueue())
    assert wait_until(lambda: src.status == "error")
    src.stop()
    assert "no depth frame" in src.error and "unplugged" in src.error


def test_stop_keeps_a_thread_that_has_not_ended_and_start_refuses_a_second_one(rng):
    import threading

    release = threading.Event()

    class Stuck(FakeProducer):  # a read that ignores stop() for a while (a USB transfer in flight)
        def read(self, timeout):
            release.wait(10)
            return None

    prod = Stuck([])
    src = UsbKinectSource(factory=lambda: prod)
    src.start(FrameQueue())
    src.stop(timeout=0.05)
    assert src.alive and not prod.closed  # nothing closed under the running reader
    with pytest.raises(SourceError, match="still running"):
        src.start(FrameQueue())
    release.set()
    assert wait_until(lambda: not src.alive)
    src.stop()
    assert prod.closed
    src.start(FrameQueue())  # the old reader has ended: a restart is fine
    src.stop()
    assert not src.alive


def test_usb_fails_at_once_when_the_stream_is_in_a_failed_state(monkeypatch):
    class NoLibusb(FakeProducer):
        class stream:
            class status:
                state = "error"
                message = "libusb-1.0 could not be loaded, so USB devices cannot be opened"

    monkeypatch.setattr(UsbKinectSource, "NO_FRAME_TIMEOUT", 600.0)  # only the failed state can end it
    src = UsbKinectSource(factory=lambda: NoLibusb([]))
    src.start(FrameQueue())
    assert wait_until(lambda: src.status == "error")
    src.stop()
    assert src.error == "USB Kinect: libusb-1.0 could not be loaded, so USB devices cannot be opened"
    assert "no depth frame received" in src.idle_reason()
