"""The USB Kinect service behind the "USB Kinect" sub-panel (ui/usb_panel.py): device discovery, the simulated
Kinect, the panel's own depth stream, motor commands, and the live depth preview (the segmented person with
the fitted skeleton when the tracker runs).

Threads here never touch bpy: discovery, the simulated Kinect's preparation and the depth stream run on
threads and leave plain Python results behind; `update_preview()` (a `bpy.app.timers` callback, a few times
per second while something runs) picks them up on the main thread. Headless code calls it directly, since
timers do not fire while a script blocks.
"""
from __future__ import annotations

import threading

import bpy
import bpy.utils.previews
import numpy as np

from ...device import DepthStream, KinectError, depth_preview, list_devices, open_motor
from ...sources import SourceError, UsbKinectSource, open_source
from . import live_runtime

PREVIEW_INTERVAL = 0.2          # seconds: 5 preview updates per second are plenty and cost the UI ~nothing
PREVIEW_SCALE = 2               # 640x480 depth -> a 320x240 preview
PREVIEW_SHAPE = (480 // PREVIEW_SCALE, 640 // PREVIEW_SCALE)
IMAGE_NAME = "Kinect Depth Preview"
SIM_FRAMES = 90                 # three seconds of rendered motion, looped by the emulated Kinect
THREAD_JOIN_S = 1.0             # how long unregister waits for a helper thread


# -- runtime state (never saved in the .blend) ------------------------------------------------------------------
class _Runtime:
    def __init__(self):
        self.devices: list[dict] | None = None      # None: not looked yet
        self.discovery_error = ""
        self.discovery: threading.Thread | None = None
        self.discovery_result: tuple[list[dict], str] | None = None
        self.stream: DepthStream | None = None      # the panel's own preview stream (not live's)
        self.sim_backend = None                     # the emulated Kinect (sim/), once prepared
        self.sim_label = ""
        self.sim_error = ""
        self.sim_thread: threading.Thread | None = None
        self.previews = None                        # bpy.utils.previews collection
        self.preview_kind = ""                      # "skeleton", "depth" or ""
        self.preview_frame = None                   # identity of the frame last shown


_rt = _Runtime()
_sim_lock = threading.Lock()   # discovery (a thread) and the main thread may both ask for the simulated Kinect


def _device_summary(info) -> dict:
    return {"model": info.model, "serial": info.serial, "camera_available": info.camera_available,
            "motor_available": info.motor_available, "motor_note": info.motor_note, "problem": info.problem}


# -- the simulated Kinect ---------------------------------------------------------------------------------------
def simulated_images() -> tuple[list[np.ndarray], str]:
    """Raw depth frames for the emulated Kinect (rendered real motion, else the synthetic figure)."""
    from ...sources.simulated_kinect import simulated_images as images
    return images(SIM_FRAMES)


def _prepare_simulated() -> None:
    try:
        images, label = simulated_images()
        from ...sources.simulated_kinect import emulated_kinect
        _rt.sim_backend, _rt.sim_label = emulated_kinect(images), label
    except Exception as exc:  # a thread must leave a sentence, not a traceback
        _rt.sim_error = f"the simulated Kinect could not be prepared ({type(exc).__name__}: {exc})"


def simulated_backend(wait: float | None = 0.0):
    """The emulated Kinect (one per session, so its motor keeps its angle). Preparing it renders depth the
    first time, so that runs on a thread: None while it is not ready after `wait` seconds."""
    with _sim_lock:
        thread = _rt.sim_thread
        if _rt.sim_backend is None and thread is None:
            _rt.sim_error = ""
            thread = _rt.sim_thread = threading.Thread(target=_prepare_simulated, name="kinect_retarget-simulate",
                                                       daemon=True)
            thread.start()
    if _rt.sim_backend is None and thread is not None:
        thread.join(wait)
        with _sim_lock:
            if not thread.is_alive() and _rt.sim_thread is thread:
                _rt.sim_thread = None   # done (or failed: the next call tries again)
    return _rt.sim_backend


def _preparing_simulated() -> bool:
    return _rt.sim_thread is not None and _rt.sim_thread.is_alive()


def _settings(context=None):
    context = context or bpy.context
    return getattr(context.scene, "kinect_retarget_usb", None)


def _simulate(context=None) -> bool:
    s = _settings(context)
    return bool(s and s.simulate)


def _backend(context=None):
    """The pyusb backend to use: the emulated Kinect when simulating (SourceError while it is being prepared),
    None for real USB (pyusb's libusb1 backend)."""
    return _simulated_or_error() if _simulate(context) else None


def _simulated_or_error():
    backend = simulated_backend()
    if backend is None:
        ensure_timer()   # the panel redraws when the preparation ends
        raise SourceError(_rt.sim_error or "the simulated Kinect is being prepared (rendering depth the first "
                                           "time takes about a minute); try again in a moment")
    return backend


# -- discovery on a thread --------------------------------------------------------------------------------------
def _discover(simulate: bool) -> None:
    try:
        backend = None
        if simulate:
            backend = simulated_backend(wait=None)
            if backend is None:
                raise KinectError(_rt.sim_error)
        _rt.discovery_result = ([_device_summary(k) for k in list_devices(backend)], "")
    except KinectError as exc:
        _rt.discovery_result = ([], str(exc))
    except Exception as exc:  # e.g. a USB stack error we did not foresee: say it, keep the UI alive
        _rt.discovery_result = ([], f"looking for Kinects failed ({type(exc).__name__}: {exc})")


def refresh_devices(context=None) -> bool:
    """Look for Kinects on a thread; the preview timer picks up the answer. False if a search is running."""
    if discovering():
        return False
    _rt.discovery_result = None
    _rt.discovery = threading.Thread(target=_discover, args=(_simulate(context),),
                                     name="kinect_retarget-discovery", daemon=True)
    _rt.discovery.start()
    ensure_timer()
    return True


def discovering() -> bool:
    return _rt.discovery is not None and _rt.discovery.is_alive()


def wait_for_discovery(timeout: float = 10.0) -> bool:
    """For scripts and tests: wait for a search to end and take its answer (True if there is one)."""
    if _rt.discovery is not None:
        _rt.discovery.join(timeout)
    return _collect_discovery()


def _collect_discovery() -> bool:
    if discovering() or _rt.discovery_result is None:
        return False
    _rt.devices, _rt.discovery_error = _rt.discovery_result
    _rt.discovery_result, _rt.discovery = None, None
    return True


def devices() -> list[dict] | None:
    return _rt.devices


# -- the panel's own depth stream -----------------------------------------------------------------------------
def _live_producer():
    """The live session's skeleton producer when live runs on the USB Kinect, else None."""
    c = live_runtime.controller()
    src = c.session.source if c is not None else None
    return src.producer if isinstance(src, UsbKinectSource) else None


def live_uses_usb() -> bool:
    c = live_runtime.controller()
    return c is not None and isinstance(c.session.source, UsbKinectSource)


def start_stream(context=None) -> DepthStream:
    """Stream depth for the preview without tracking (live opens its own stream)."""
    if live_uses_usb():
        raise SourceError("live is using the Kinect; its preview is shown already")
    if _rt.stream is None or not _rt.stream.running:
        _rt.stream = DepthStream(_backend(context), queue_size=2).start()
    ensure_timer()
    return _rt.stream


def stop_stream() -> bool:
    """Stop the panel's stream (True when its thread ended). Its last status stays on show."""
    stream = _rt.stream
    return stream.stop() if stream is not None else True


def stream_running() -> bool:
    return _rt.stream is not None and _rt.stream.running


def stream_status():
    """StreamStatus of the stream on show: live's when live runs on the Kinect, else the panel's."""
    producer = _live_producer()
    stream = getattr(producer, "stream", None) if producer is not None else _rt.stream
    return getattr(stream, "status", None)


# -- the preview image --------------------------------------------------------------------------------------
def _grey_rgba(mm: np.ndarray) -> np.ndarray:
    grey = depth_preview(mm, PREVIEW_SHAPE).astype(np.float32)[::-1] / 255.0   # Blender rows are bottom-up
    rgba = np.empty(grey.shape + (4,), np.float32)
    rgba[..., :3] = grey[..., None]
    rgba[..., 3] = 1.0
    return rgba


def _next_rgba():
    """(rgba, kind, frame identity) of the newest frame not shown yet, or None."""
    producer = _live_producer()
    if producer is not None:
        preview = getattr(producer, "preview", None)
        p = preview() if callable(preview) else None
        if p is None or (_rt.preview_kind == "skeleton" and p is _rt.preview_frame):
            return None
        from ...depth.tracking_preview import preview_rgba
        camera = getattr(getattr(producer, "tracker", None), "camera", None)
        return preview_rgba(*p, camera=camera, scale=PREVIEW_SCALE), "skeleton", p
    frame = _rt.stream.latest_frame() if _rt.stream is not None else None
    if frame is None or frame.mm is None:
        return None
    return _grey_rgba(frame.mm), "depth", frame.index


def preview_image():
    return bpy.data.images.get(IMAGE_NAME)


def _upload(rgba: np.ndarray) -> None:
    h, w = rgba.shape[:2]
    flat = np.ascontiguousarray(rgba, dtype=np.float32).ravel()
    img = preview_image()
    if img is None or tuple(img.size) != (w, h):
        if img is not None:
            bpy.data.images.remove(img)
        img = bpy.data.images.new(IMAGE_NAME, w, h, alpha=True)
    img.pixels.foreach_set(flat)
    img.update()
    if _rt.previews is not None:   # the sidebar shows it through a custom preview (template_icon)
        icon = _rt.previews.get("depth") or _rt.previews.new("depth")
        if tuple(icon.image_size) != (w, h):
            icon.image_size = (w, h)   # reallocates: only when the size changes
        icon.image_pixels_float.foreach_set(flat)   # drawn from these pixels on the next redraw


def update_preview() -> float | None:
    """The timer: take discovery results, free the device for live, show the newest depth frame.
    Returns the next interval, or None (timer ends) when nothing is running."""
    try:
        changed = _collect_discovery()
        if live_uses_usb() and stream_running():
            stop_stream()   # live has its own stream; one Kinect cannot be opened twice
        nxt = _next_rgba()
        if nxt is not None:
            rgba, _rt.preview_kind, _rt.preview_frame = nxt
            _upload(rgba)
            changed = True
        if changed:
            live_runtime.redraw_3d_views()
    except Exception as exc:  # a timer that raises is dropped silently by Blender: say it, and go on
        print(f"kinect_retarget: depth preview: {type(exc).__name__}: {exc}")
    busy = discovering() or _preparing_simulated() or stream_running() or live_uses_usb()
    return PREVIEW_INTERVAL if busy else None


def ensure_timer() -> None:
    if not bpy.app.timers.is_registered(update_preview):
        # persistent: a stream outlives a file load, so must the timer that shows it (the image is recreated)
        bpy.app.timers.register(update_preview, first_interval=0.0, persistent=True)


# -- live on the USB Kinect ------------------------------------------------------------------------------------
def live_usb_source(context) -> tuple[UsbKinectSource, str]:
    """The USB source for live (live_runtime.source_from_scene) and its label: the simulated Kinect when chosen,
    and the device freed from the panel's own preview stream first."""
    stop_stream()
    usb = getattr(context.scene, "kinect_retarget_usb", None)
    simulated = usb is not None and usb.simulate
    source = open_source("usb", usb_backend=_simulated_or_error() if simulated else None)
    ensure_timer()
    return source, "simulated USB Kinect" if simulated else "USB Kinect"


def with_motor(context, action):
    """Open the motor (the simulated Kinect's when simulating), run `action(motor)`, close it; the result."""
    motor = open_motor(_backend(context))
    try:
        return action(motor)
    finally:
        motor.close()


def simulate_changed(context) -> None:
    """The simulated toggle flipped: the stream and the device list described the other kind of device."""
    stop_stream()
    _rt.devices, _rt.discovery_error = None, ""
    refresh_devices(context)


def runtime() -> _Runtime:
    """The service's state, for the panel to draw (read only)."""
    return _rt


def settings(context=None):
    """The scene's USB settings (ui/usb_panel.py registers them), or None."""
    return _settings(context)


def preparing_simulated() -> bool:
    return _preparing_simulated()


# -- registration ---------------------------------------------------------------------------------------------
def register_extra() -> None:
    _rt.previews = bpy.utils.previews.new()


def unregister_extra() -> None:
    """Undo everything: the timer, the panel's stream, helper threads, the preview."""
    if bpy.app.timers.is_registered(update_preview):
        bpy.app.timers.unregister(update_preview)
    stop_stream()
    _rt.stream = None
    for thread in (_rt.discovery, _rt.sim_thread):
        if thread is not None:
            thread.join(THREAD_JOIN_S)   # short ones; a first render cannot be interrupted (it touches no bpy)
    _rt.discovery = _rt.sim_thread = _rt.discovery_result = None
    if _rt.previews is not None:
        bpy.utils.previews.remove(_rt.previews)
        _rt.previews = None
    img = preview_image()
    if img is not None:
        bpy.data.images.remove(img)
    _rt.preview_kind, _rt.preview_frame = "", None
