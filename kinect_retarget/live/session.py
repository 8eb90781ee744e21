"""The live pump, shared by the Blender timer and headless loops.

`pump()` runs on the main thread: it drains the queue, feeds *every* frame through the same stateful
pipeline as the bake (so filters see what the recording will see, and live equals baked), records every
frame, and hands only the newest pose to `apply` (the costly bpy part). Frames drained together with a
newer one are counted as superseded; a newest frame older than `stale_after` is not shown (stale).
"""
from __future__ import annotations

import os
import time
from typing import Callable

import numpy as np

from ..core.skeletons import NOT_TRACKED
from ..core.performer_calibration import CalibrationCapture
from ..sources.frame_queue import FrameQueue
from .recording import Recorder
from .stats import LiveStats


class LiveError(RuntimeError):
    """Live had to stop: the message is for the user."""


class LiveSession:
    def __init__(self, source, pipeline, apply: Callable, *, queue: FrameQueue | None = None,
                 stale_after: float = 0.25, lost_tracking_timeout: float = 2.0,
                 clock: Callable[[], float] = time.perf_counter):
        self.source = source
        self.pipeline = pipeline
        self.apply = apply
        self.queue = queue or FrameQueue()
        self.stale_after = stale_after
        self.lost_tracking_timeout = lost_tracking_timeout
        self.clock = clock
        self.stats = LiveStats()
        self.recorder: Recorder | None = None
        self.error: str | None = None
        self.running = False
        self.last_pose = None
        self.last_frame = None  # the newest frame with a tracked joint (the 3D View's source skeleton)
        self.last_tracked_joints = 0
        self._t0_source: float | None = None   # source clock of the first frame
        self._t0_session = 0.0                 # session clock of the first frame
        self._last_tracked_time: float | None = None
        self._pipe_offset = 0.0  # pipeline clock = session clock - offset (the recording's, once one started)
        self._calibration: tuple[CalibrationCapture, Callable] | None = None

    # -- lifecycle -------------------------------------------------------------------------------------
    def start(self) -> None:
        self.start_clock = self.clock()
        self._reset_pipeline()
        self.source.start(self.queue)  # SourceError propagates: nothing was started
        self.running = True

    def _reset_pipeline(self) -> None:
        self.pipeline.reset(self.source.rate)

    def now(self) -> float:
        """Seconds since start on the session clock."""
        return self.clock() - self.start_clock

    def start_recording(self, path: str | os.PathLike, metadata: dict | None = None) -> Recorder:
        if self.recorder is not None:
            raise LiveError(f"already recording to {self.recorder.path}")
        self.recorder = Recorder(path, self.source.skeleton, self.source.rate, self.now(), metadata)
        self._pipe_offset = self.recorder.start_time
        # The bake replays the recording from a fresh pipeline: restart filters and the root reference
        # here too, so what was seen live is exactly what gets keyed.
        self._reset_pipeline()
        return self.recorder

    def stop_recording(self) -> str | None:
        """Close the recording (whatever was written stays on disk); returns its path."""
        rec, self.recorder = self.recorder, None
        if rec is None:
            return None
        rec.close()
        return rec.path if rec.frames else None

    def start_calibration(self, done: Callable[[CalibrationCapture], None], duration: float = 1.0) -> None:
        """Collect `duration` seconds of frames; `done(capture)` runs on the main thread when full."""
        self._calibration = (CalibrationCapture(duration), done)

    @property
    def calibrating(self) -> bool:
        return self._calibration is not None

    def stop(self, error: str | None = None) -> None:
        """Idempotent. Ends the thread first so nothing is written after the recording closes."""
        if error and not self.error:
            self.error = error
        self.source.stop()
        if self.recorder is not None:
            self.recorder.close()
        self.running = False

    # -- the pump --------------------------------------------------------------------------------------
    def pump(self) -> bool:
        """One main-thread step; returns False once live has stopped (see `error`)."""
        if not self.running:
            return False
        frames = self.queue.drain()
        times = np.empty(len(frames))
        last_tracked, lost = None, None
        for k, frame in enumerate(frames):
            self.stats.received += 1
            self.stats.rate.add(frame.arrival)
            ts = self._session_time(frame)
            if self.recorder is not None:
                times[k] = self.recorder.write(ts, frame.positions, frame.states)  # exactly the stored time
                self.stats.recorded += 1
            else:
                times[k] = ts - self._pipe_offset
            if self._calibration is not None and self._calibration[0].add(ts, frame.positions, frame.states):
                capture, done = self._calibration
                self._calibration = None
                done(capture)
            tracked = int(np.count_nonzero(frame.states != NOT_TRACKED))
            if tracked == 0:
                self.stats.untracked += 1
                lost = lost or self._lost_tracking(ts)  # stop after the loop: every drained frame is recorded
                continue
            lost = None  # tracking came back within this batch: only a loss at its end counts
            self._last_tracked_time = ts
            self.last_tracked_joints = tracked
            if last_tracked is not None:
                self.stats.superseded += 1
            last_tracked = self.last_frame = frame
        if lost:
            self.stop(lost)
            return False
        newest = None
        if last_tracked is not None:
            try:
                # every drained frame goes through the filter (live equals the bake); only the newest is solved
                pose = self.pipeline.process_frames(np.stack([f.positions for f in frames]),
                                                    np.stack([f.states for f in frames]), times)
            except Exception as exc:  # the engine names the problem; live must stop, not crash the host
                self.stop(f"retarget failed near frame {self.stats.received}: {exc}")
                return False
            if pose is not None:
                newest = (last_tracked, pose)
        if not self.running:
            return False
        if newest is not None:
            frame, pose = newest
            if self.clock() - frame.arrival > self.stale_after:
                self.stats.stale += 1
            else:
                try:
                    self.apply(pose)
                except Exception as exc:
                    self.stop(f"could not pose the rig: {exc}")
                    return False
                self.last_pose = pose
                self.stats.applied += 1
                self.stats.latency.add(self.clock() - frame.arrival)
        if self.source.error and len(self.queue) == 0:  # frames sent before the failure are recorded first
            self.stop(self.source.error)
            return False
        if not self.source.alive and self.source.status != "running" and len(self.queue) == 0:
            self.stop()  # the take ended: not an error
            return False
        return True

    def _session_time(self, frame) -> float:
        if self._t0_source is None:
            self._t0_source = frame.time_s
            self._t0_session = frame.arrival - self.start_clock
        return self._t0_session + (frame.time_s - self._t0_source)

    def _lost_tracking(self, t: float) -> str | None:
        since = self._last_tracked_time if self._last_tracked_time is not None else self._t0_session
        if t - since > self.lost_tracking_timeout:
            return (f"{self.source.describe()}: no tracked joints for {t - since:.1f} s "
                    f"(frame {self.stats.received}); is the performer in view?")
        return None

    def statistics(self) -> dict:
        return self.stats.as_dict(self.queue.overflowed)

    def run_for(self, seconds: float, interval: float = 1 / 120) -> None:
        """Headless loop: timers do not fire while a script blocks, so call the pump ourselves."""
        end = self.clock() + seconds
        while self.running and self.clock() < end:
            self.pump()
            time.sleep(interval)
