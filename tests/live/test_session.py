import time

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V2, NOT_TRACKED
from kinect_retarget.sources.skeleton_frame import SkeletonFrame
from kinect_retarget.sources.frame_queue import FrameQueue
from kinect_retarget.live.session import LiveSession
from kinect_retarget.sources import TakePlayback
from kinect_retarget.sources.frame_source import FrameSource
from kinect_retarget.takes import krtake


def run_to_end(session, timeout=10.0):
    end = time.perf_counter() + timeout
    while session.pump() and time.perf_counter() < end:
        time.sleep(0.002)
    assert not session.running


def test_pump_records_every_frame_and_applies_the_newest(wave_take, stand_in, tmp_path):
    applied = []
    s = LiveSession(TakePlayback(wave_take, speed=8.0), stand_in, applied.append)
    s.start()
    s.start_recording(tmp_path / "rec.krtake")
    run_to_end(s)
    path = s.stop_recording()
    st = s.statistics()
    assert st["received"] == wave_take.frame_count == st["recorded"]
    assert stand_in.calls == wave_take.frame_count  # every frame went through the filter
    assert st["applied"] == len(applied) > 0
    assert st["applied"] + st["dropped"] + st["untracked"] == st["received"]
    rec = krtake.read(path)
    assert rec.frame_count == wave_take.frame_count
    np.testing.assert_allclose(rec.positions, wave_take.positions, atol=1e-5)  # 5 decimals on disk
    np.testing.assert_array_equal(rec.states, wave_take.states)
    # the recording's clock is the live clock: 8x playback lasts 1/8 of the take
    assert rec.duration == pytest.approx(wave_take.duration / 8, abs=0.05)
    assert not s.source.alive


def test_live_pose_equals_replaying_the_recording(wave_take, stand_in, tmp_path):
    """Same frames, same times, same stateful pipeline: the applied pose is the replayed one."""
    applied = []
    s = LiveSession(TakePlayback(wave_take, speed=4.0), stand_in, applied.append)
    s.start()
    s.start_recording(tmp_path / "rec.krtake")
    run_to_end(s)
    rec = krtake.read(s.stop_recording())
    stand_in.reset()
    replay = [stand_in.process_frame(p, st, 0.0) for p, st in zip(rec.positions, rec.states)]
    assert len(applied) > 10
    for pose in applied:  # the file keeps 5 decimals, hence the tolerance
        np.testing.assert_allclose(pose.root_location, replay[pose.index].root_location, atol=2e-5)


class ScriptedSource(FrameSource):
    """Emits prepared frames at a fixed pace; then fails with `error` if given."""
    kind = "scripted"

    def __init__(self, positions, states, dt=0.002, error=None):
        super().__init__(KINECT_V2, 30.0)
        self.positions, self.states, self.dt, self.err = positions, states, dt, error

    def _run(self):
        for i in range(len(self.positions)):
            if not self._sleep(self.dt):
                return
            self._emit(self.positions[i], self.states[i], i / 30.0, where=f" frame {i}")
        if self.err:
            raise OSError(self.err)


def test_source_error_stops_live_and_keeps_the_recording(wave_take, stand_in, tmp_path):
    src = ScriptedSource(wave_take.positions[:20], wave_take.states[:20], error="socket closed by peer")
    s = LiveSession(src, stand_in, lambda pose: None)
    s.start()
    s.start_recording(tmp_path / "rec.krtake")
    run_to_end(s)
    assert "socket closed by peer" in s.error
    path = s.stop_recording()
    assert krtake.read(path).frame_count == 20
    assert not src.alive


def test_nan_frame_stops_live_naming_frame_and_joint(wave_take, stand_in, tmp_path):
    pos = wave_take.positions[:10].copy()
    pos[6, KINECT_V2.index("ElbowRight")] = np.nan
    src = ScriptedSource(pos, wave_take.states[:10])
    s = LiveSession(src, stand_in, lambda pose: None)
    s.start()
    s.start_recording(tmp_path / "rec.krtake")
    run_to_end(s)
    assert "frame 6" in s.error and "ElbowRight" in s.error and "NaN" in s.error
    assert krtake.read(s.stop_recording()).frame_count == 6


def test_no_tracked_joints_holds_the_pose_then_stops(wave_take, stand_in, tmp_path):
    n = 40
    states = wave_take.states[:n].copy()
    states[5] = NOT_TRACKED            # one lost frame: pose held, live goes on
    states[10:] = NOT_TRACKED          # then the performer is gone for > timeout
    src = ScriptedSource(wave_take.positions[:n], states)
    applied = []
    s = LiveSession(src, stand_in, applied.append, lost_tracking_timeout=0.5)
    s.start()
    s.start_recording(tmp_path / "rec.krtake")
    run_to_end(s)
    assert "no tracked joints" in s.error
    assert s.stats.untracked >= 16
    assert krtake.read(s.stop_recording()).frame_count >= 26  # everything up to the stop is kept
    assert len(applied) >= 1


def test_engine_exception_stops_live_with_message(wave_take, tmp_path):
    class Broken:
        def reset(self, rate=30.0):
            pass

        def process_frames(self, *a):
            raise ValueError("mapping names bone 'Spine' which the rig lacks")
    s = LiveSession(TakePlayback(wave_take, speed=10), Broken(), lambda p: None)
    s.start()
    run_to_end(s)
    assert "retarget failed" in s.error and "Spine" in s.error
    assert not s.source.alive


def test_queue_overflow_drops_oldest_and_counts():
    q = FrameQueue(capacity=3)
    for i in range(5):
        q.put(SkeletonFrame(np.zeros((25, 3)), np.zeros(25, np.uint8), float(i), 0.0))
    assert [f.time_s for f in q.drain()] == [2.0, 3.0, 4.0]
    assert q.overflowed == 2 and len(q) == 0


def test_stale_frames_are_not_shown(wave_take, stand_in):
    now = [100.0]
    s = LiveSession(TakePlayback(wave_take), stand_in, lambda p: pytest.fail("stale frame applied"),
                    stale_after=0.1, clock=lambda: now[0])
    s.running, s.start_clock = True, 0.0
    s.source.status = "running"
    s.queue.put(SkeletonFrame(wave_take.positions[0], wave_take.states[0], 0.0, 99.5))
    s.pump()
    assert s.stats.stale == 1 and s.stats.applied == 0


def test_tracking_back_within_one_batch_is_not_lost(wave_take, stand_in):
    """A stalled main thread drains a gap longer than the timeout followed by tracked frames: live goes on."""
    now = [100.0]
    applied = []
    s = LiveSession(TakePlayback(wave_take), stand_in, applied.append, lost_tracking_timeout=0.5,
                    clock=lambda: now[0])
    s.running, s.start_clock = True, 0.0
    s.source.status = "running"
    for i in range(30):  # 1 s at 30 fps: tracked, then 0.9 s without anyone, then tracked again
        states = wave_take.states[i] if i < 2 or i > 28 else np.zeros_like(wave_take.states[i])
        s.queue.put(SkeletonFrame(wave_take.positions[i], states, i / 30.0, 100.0))
    assert s.pump(), s.error
    assert s.error is None and s.running and len(applied) == 1
    # the same gap at the end of a batch still stops live
    for i in range(30, 60):
        s.queue.put(SkeletonFrame(wave_take.positions[i], np.zeros_like(wave_take.states[i]), i / 30.0, 100.0))
    assert not s.pump() and "no tracked joints" in s.error
