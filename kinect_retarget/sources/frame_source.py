"""The frame-source interface: a thread that puts whole SkeletonFrames on a FrameQueue.

A source never touches bpy. When it dies it records `error` (a sentence for the user) and stops; the
pump sees that and ends live cleanly. Validation happens here, on the producer side, so every source
rejects NaN the same way.
"""
from __future__ import annotations

import threading
import time

import numpy as np

from ..core.skeletons import NOT_TRACKED, Skeleton
from .frame_queue import FrameQueue
from .skeleton_frame import SkeletonFrame


class SourceError(RuntimeError):
    """A source cannot go on: the message names the source and what went wrong."""


class FrameSource:
    """Subclasses implement `_run()` (loop until `self.stopping`) and call `_emit()` per frame."""

    kind = "source"

    def __init__(self, skeleton: Skeleton, rate: float):
        self.skeleton = skeleton
        self.rate = float(rate)
        self.status = "idle"           # idle | running | finished | stopped | error
        self.error: str | None = None
        self.warning: str | None = None  # the latest problem the source got past (shown, not fatal)
        self.frames_emitted = 0
        self._queue: FrameQueue | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # -- lifecycle, called from the main thread --------------------------------------------------------
    def start(self, queue: FrameQueue) -> None:
        if self._thread is not None and self._thread.is_alive():
            raise SourceError(f"{self.describe()} is still running; stop it (and let it end) first")
        self._thread = None
        self._queue = queue
        self._stop.clear()
        self._open()  # may raise SourceError synchronously (missing file, port in use)
        self.status = "running"
        self._thread = threading.Thread(target=self._run_guarded, name=f"kinect_retarget-{self.kind}",
                                        daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 2.0) -> None:
        self._stop.set()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout)
        if thread is not None and thread.is_alive():
            return  # still blocked in a read: keep it (start() refuses) and close nothing under its feet
        self._thread = None
        self._close()
        if self.status == "running":
            self.status = "stopped"

    @property
    def alive(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    @property
    def stopping(self) -> bool:
        return self._stop.is_set()

    def describe(self) -> str:
        return self.kind

    # -- for subclasses ----------------------------------------------------------------------------
    def _open(self) -> None:
        """Acquire resources before the thread starts (raise SourceError to refuse)."""

    def _close(self) -> None:
        """Release resources after the thread ended."""

    def _run(self) -> None:
        raise NotImplementedError

    def _sleep(self, seconds: float) -> bool:
        """Sleep unless asked to stop; True if the source should go on."""
        if seconds > 0:
            return not self._stop.wait(seconds)
        return not self._stop.is_set()

    def _emit(self, positions: np.ndarray, states: np.ndarray, time_s: float, where: str = "",
              body: int = 0) -> None:
        positions = np.asarray(positions, dtype=np.float64)
        states = np.asarray(states, dtype=np.uint8)
        j = len(self.skeleton)
        if positions.shape != (j, 3) or states.shape != (j,):
            raise SourceError(f"{self.describe()}{where}: frame has shape {positions.shape}/{states.shape}, "
                              f"expected ({j}, 3)/({j},)")
        bad = (states != NOT_TRACKED) & ~np.all(np.isfinite(positions), axis=1)
        if bad.any():
            names = ", ".join(self.skeleton.joints[k] for k in np.flatnonzero(bad)[:3])
            raise SourceError(f"{self.describe()}{where}: NaN or infinite position for tracked joint {names}")
        if not np.isfinite(time_s):
            raise SourceError(f"{self.describe()}{where}: timestamp is not a number")
        positions = np.where(np.isfinite(positions), positions, 0.0)
        assert self._queue is not None
        self._queue.put(SkeletonFrame(positions, states, float(time_s), time.perf_counter(), body))
        self.frames_emitted += 1

    def fail(self, message: str) -> None:
        self.error = message
        self.status = "error"
        self._stop.set()

    def _run_guarded(self) -> None:
        try:
            self._run()
            if self.status == "running":
                self.status = "stopped" if self._stop.is_set() else "finished"
        except SourceError as exc:
            self.fail(str(exc))
        except OSError as exc:  # socket or file trouble on the thread
            self.fail(f"{self.describe()}: {exc.strerror or exc}")
        except Exception as exc:  # keep the thread from dying silently; the pump reports it
            self.fail(f"{self.describe()}: unexpected {type(exc).__name__}: {exc}")
