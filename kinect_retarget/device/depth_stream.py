"""DepthStream: a background thread that reads depth frames from a Kinect into a bounded queue.

The thread owns the USB side (open, iso pump, reassembly, unpacking, raw->mm) and never touches bpy; the
main thread takes whole DepthFrame objects from `frames`. Hot-plug: when the device disappears the status
says so, frames already queued stay there, and the thread reconnects by itself when the Kinect comes back.
"""
from __future__ import annotations

import collections
import logging
import queue
import threading
import time
from dataclasses import dataclass, replace

import numpy as np
import usb.core

from .disparity_calibration import Calibration
from .kinect_camera import KinectCamera, usb_failure
from .decode import decode_frame
from .discovery import KinectInfo, find_kinect
from .errors import DeviceGone, DeviceNotFound, KinectError
from .motor import send_keep_alive
from .protocol import DEPTH_ENDPOINT, is_model_1414
from .reassembly import FrameAssembler
from .usb_backend import DEFAULT_PACKETS_PER_TRANSFER, DEFAULT_TRANSFERS, open_iso_pump

log = logging.getLogger(__name__)

STOPPED, CONNECTING, STREAMING, UNPLUGGED, WAITING, ERROR = (
    "stopped", "connecting", "streaming", "unplugged", "waiting for device", "error")


NO_FRAME_TIMEOUT_S = 2.0      # a stream that delivers no frame this long says why it probably does not


def no_frame_diagnosis(packets: int, seconds: float) -> str:
    """What a started stream that delivers no frame for `seconds` most likely means."""
    if packets == 0:
        return (f"streaming, but no depth data arrived for {seconds:g} s. Likely causes: the Kinect's 12 V adapter "
                "is unplugged (its camera enumerates but the projector and sensor stay off); the USB controller "
                "does not deliver isochronous data from it (some USB 3 controllers: try a USB 2 port, or a USB 2 "
                "hub); another program or camera is using the same controller")
    return (f"streaming, but no complete depth frame for {seconds:g} s although {packets} packets arrived: too "
            "many are lost. Likely causes: other devices on the same USB controller take its bandwidth (unplug "
            "other cameras, or use a port on another controller); a USB 3 controller that mangles isochronous "
            "data (try a USB 2 port or a USB 2 hub); a damaged cable or unpowered hub")


@dataclass(frozen=True)
class DepthFrame:
    raw: np.ndarray            # (480, 640) uint16, 11-bit disparity, 2047 = no reading
    mm: np.ndarray | None      # (480, 640) uint16 millimetres, 0 = no reading (None if conversion is off)
    timestamp: int             # device ticks, 60 MHz, wraps at 2**32
    index: int                 # 0, 1, 2 ... in delivery order for this DepthStream
    received: float            # time.monotonic() when the frame was complete
    lost_packets: int          # packets missing in this frame (their pixels read no-reading)
    calibration: Calibration


@dataclass(frozen=True)
class StreamStatus:
    state: str                 # one of STOPPED, CONNECTING, STREAMING, UNPLUGGED, WAITING, ERROR
    message: str               # a sentence for the UI
    fps: float                 # delivered frames per second over the last second or so
    frames: int                # frames delivered since start()
    frames_dropped: int        # frames the device sent that were not delivered (packet loss)
    queue_overflows: int       # frames discarded because the consumer did not keep up
    packets_lost: int
    device: str                # model and serial, once known
    reconnects: int
    thread_cpu_s: float        # CPU time used by the streaming thread


class DepthStream:
    """Depth frames from a Kinect (real or emulated) on a background thread.

    source: None (first Kinect found through libusb), a pyusb backend (e.g. EmulatedKinect), or a KinectInfo.
    serial: pick a specific Kinect. queue_size: frames buffered for the consumer; when full, the oldest is
    discarded (live use wants the newest). packet_hook(packets) sees every poll's packets (for dumps).
    """

    def __init__(self, source=None, *, serial: str | None = None, queue_size: int = 8, convert_mm: bool = True,
                 packet_hook=None, transfers: int = DEFAULT_TRANSFERS,
                 packets_per_transfer: int = DEFAULT_PACKETS_PER_TRANSFER, reconnect_interval: float = 0.25,
                 poll_timeout: float = 0.02, no_frame_timeout: float = NO_FRAME_TIMEOUT_S):
        if isinstance(source, KinectInfo):
            self._backend, serial = source.camera._ctx.backend, serial or source.serial
        else:
            self._backend = source
        self.serial = serial
        self.frames: queue.Queue[DepthFrame] = queue.Queue(maxsize=queue_size)
        self.convert_mm = convert_mm
        self.packet_hook = packet_hook
        self._transfers, self._ppt = transfers, packets_per_transfer
        self.reconnect_interval = reconnect_interval
        self.poll_timeout = poll_timeout
        self.no_frame_timeout = no_frame_timeout
        self._streaming_message = ""
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()
        self._status = StreamStatus(STOPPED, "not started", 0.0, 0, 0, 0, 0, "", 0, 0.0)
        self._recent = collections.deque(maxlen=31)
        self._stuck: list = []     # (pump, camera) whose transfers libusb never handed back

    # --- public API ---------------------------------------------------------------------------------------
    @property
    def status(self) -> StreamStatus:
        with self._lock:
            status = self._status
        if self._recent and time.monotonic() - self._recent[-1] > 1.0:
            status = replace(status, fps=0.0)
        return status

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def latest_frame(self) -> DepthFrame | None:
        """Empty the queue and return the newest frame (None if none arrived): for a live preview that
        polls a few times per second from the main thread."""
        frame = None
        while True:
            try:
                frame = self.frames.get_nowait()
            except queue.Empty:
                return frame

    def start(self) -> "DepthStream":
        if self.running:
            return self
        self._stop.clear()
        self._set(state=CONNECTING, message="looking for a Kinect", frames=0, frames_dropped=0,
                  queue_overflows=0, packets_lost=0, reconnects=0)
        self._thread = threading.Thread(target=self._run, name="kinect-depth", daemon=True)
        self._thread.start()
        return self

    def stop(self, timeout: float = 1.0) -> bool:
        """Ask the thread to stop and wait for it; True if it ended within `timeout` seconds."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout)
            if self._thread.is_alive():
                return False
        self._thread = None
        return True

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()

    # --- the thread ---------------------------------------------------------------------------------------
    def _set(self, **fields) -> None:
        with self._lock:
            self._status = replace(self._status, **fields)

    def _run(self) -> None:
        had_device = False
        try:
            while not self._stop.is_set():
                try:
                    self._stream_once()
                    break                                     # asked to stop
                except DeviceGone as exc:
                    had_device = True
                    self._set(state=UNPLUGGED, fps=0.0,
                              message=f"{exc}: {self._status.frames} frames kept; waiting for it to come back",
                              reconnects=self._status.reconnects + 1)
                except DeviceNotFound as exc:
                    self._set(state=UNPLUGGED if had_device else WAITING, fps=0.0,
                              message=(f"Kinect unplugged: {self._status.frames} frames kept; waiting for it "
                                       "to come back") if had_device else str(exc))
                except KinectError as exc:
                    self._set(state=ERROR, message=str(exc), fps=0.0)
                except Exception as exc:                      # keep the thread alive and say what happened
                    log.exception("depth stream failed")
                    self._set(state=ERROR, message=f"unexpected error: {exc!r}", fps=0.0)
                # errors (no permission, no driver) are retried too, but slowly: the user may be fixing them
                self._stop.wait(self.reconnect_interval * (4 if self._status.state == ERROR else 1))
        finally:
            stuck = f"stopped, but {self._stuck[-1][0].stuck}" if self._stuck else "stopped"
            self._set(state=STOPPED, message=stuck, fps=0.0, thread_cpu_s=time.thread_time())

    def _stream_once(self) -> None:
        info = find_kinect(self._backend, self.serial)
        if info.problem:
            raise KinectError(f"{info.model} {info.serial}: {info.problem}")
        self.serial = self.serial or info.serial
        self._set(state=CONNECTING, message=f"opening {info.model} {info.serial}",
                  device=f"{info.model} {info.serial}")
        warning = ""
        if not is_model_1414(info.camera.idProduct, info.camera.bcdDevice):
            warning = send_keep_alive(info.audio)         # before the camera is claimed, as libfreenect does
            if warning:
                log.warning("%s %s: %s", info.model, info.serial, warning)
        camera = KinectCamera(info.camera)
        pump = None
        try:
            camera.open()
            lut = camera.calibration.raw_to_mm_table()
            pump = open_iso_pump(info.camera, DEPTH_ENDPOINT, self._transfers, self._ppt)
            pump.start()                                      # transfers queued before the stream starts
            camera.start_depth()
            self._streaming_message = f"streaming from {info.model} {info.serial}" + (
                f" ({warning})" if warning else "")
            self._set(state=STREAMING, message=self._streaming_message)
            self._pump_loop(pump, camera.calibration, lut)
            try:
                camera.stop_depth()
            except KinectError:
                pass
        except usb.core.USBError as exc:
            raise usb_failure(exc, "a USB transfer") from exc
        finally:
            if pump is not None and not pump.stop():
                # libusb still owns transfers on this handle: closing it would let libusb write into freed
                # memory, so the camera and pump stay alive (and open) for good, and the status says so
                self._stuck.append((pump, camera))
                log.error("depth stream: %s", pump.stuck)
            else:
                camera.close()

    def _pump_loop(self, pump, calibration: Calibration, lut: np.ndarray) -> None:
        assembler = FrameAssembler()
        base_dropped = self._status.frames_dropped
        base_lost = self._status.packets_lost
        last_frame, frames_before, packets_seen, complained = time.monotonic(), self._status.frames, 0, False
        while not self._stop.is_set():
            packets = pump.poll(self.poll_timeout)
            if self._status.frames != frames_before:      # a frame came: the stream is fine (again)
                last_frame, frames_before, packets_seen = time.monotonic(), self._status.frames, 0
                if complained:
                    self._set(message=self._streaming_message)
                    complained = False
            elif not complained and time.monotonic() - last_frame > self.no_frame_timeout:
                self._set(message=no_frame_diagnosis(packets_seen, self.no_frame_timeout), fps=0.0)
                complained = True
            if not packets:
                continue
            packets_seen += len(packets)
            if self.packet_hook is not None:
                self.packet_hook(packets)
            for done in assembler.feed(packets):
                self._deliver(done, calibration, lut)
            stats = assembler.stats
            self._set(frames_dropped=base_dropped + stats.frames_missed, packets_lost=base_lost + stats.packets_lost,
                      thread_cpu_s=time.thread_time())

    def _deliver(self, done, calibration: Calibration, lut: np.ndarray) -> None:
        raw, mm = decode_frame(done, lut if self.convert_mm else None)
        now = time.monotonic()
        self._recent.append(now)
        fps = (len(self._recent) - 1) / (now - self._recent[0]) if len(self._recent) > 1 else 0.0
        index = self._status.frames
        frame = DepthFrame(raw, mm, done.timestamp, index, now, done.lost_packets, calibration)
        overflow = 0
        while True:
            try:
                self.frames.put_nowait(frame)
                break
            except queue.Full:
                try:
                    self.frames.get_nowait()                  # live use wants the newest frame
                    overflow += 1
                except queue.Empty:
                    pass
        self._set(frames=index + 1, fps=fps, queue_overflows=self._status.queue_overflows + overflow)
