"""`devices --diagnose`: a report for a bug report. What libusb is in use, what is on each bus, and for each
Kinect what was tried and what answered: pairing of its devices, serial, audio firmware, LED keep-alive,
opening the camera and its calibration replies, and a short depth stream. Plain text, nothing else changed.
"""
from __future__ import annotations

import platform
import sys
import time

import usb.core

from . import protocol as P
from .depth_stream import ERROR, DepthStream
from .discovery import list_devices, nothing_found_reason
from .errors import KinectError
from .kinect_camera import KinectCamera
from .motor import send_keep_alive
from .usb_backend import find_backend

STREAM_TRY_S = 3.0
_ROLES = {**{pid: "Kinect camera" for pid in P.CAMERA_PIDS}, **{pid: "Kinect motor" for pid in P.MOTOR_PIDS},
          **{pid: "Kinect audio" for pid in P.AUDIO_PIDS}, 0x02D9: "Kinect v2 (not supported)",
          0x02C4: "Kinect v2 preview (not supported)", 0x02D8: "Kinect v2 (not supported)"}


def _libusb_line(backend) -> str:
    lib = getattr(backend, "lib", None)
    name = getattr(lib, "_name", None) or type(lib).__name__
    return f"backend {type(backend).__module__}.{type(backend).__name__}, libusb {name}"


def _bus_lines(backend) -> list[str]:
    lines = []
    devices = sorted(usb.core.find(find_all=True, backend=backend), key=lambda d: (d.bus or 0, d.address or 0))
    for bus in sorted({d.bus for d in devices}, key=lambda b: b or 0):
        lines.append(f"bus {bus}:")
        for d in (d for d in devices if d.bus == bus):
            role = _ROLES.get(d.idProduct, "") if d.idVendor == P.VENDOR_MICROSOFT else ""
            ports = ".".join(map(str, d.port_numbers)) if getattr(d, "port_numbers", None) else "?"
            lines.append(f"  {d.idVendor:04x}:{d.idProduct:04x} address {d.address} port {ports}"
                         + (f"  {role}, bcdDevice {d.bcdDevice:#06x}" if role else ""))
    return lines or ["no USB device at all was listed (libusb sees nothing: permissions or a sandbox?)"]


def _try(lines: list[str], what: str, action) -> object:
    t0 = time.monotonic()
    try:
        result = action()
    except (KinectError, usb.core.USBError, NotImplementedError, ValueError) as exc:
        lines.append(f"    {what}: FAILED after {time.monotonic() - t0:.2f} s: {type(exc).__name__}: {exc}")
        return None
    lines.append(f"    {what}: {result}")
    return result


def _camera_lines(info, lines: list[str]) -> None:
    camera = KinectCamera(info.camera)

    def open_camera():
        camera.open()
        c = camera.calibration
        return (f"claimed; calibration from the {c.source}: const_shift {c.const_shift:g}, reference distance "
                f"{c.reference_distance:g} mm, pixel size {c.reference_pixel_size:g} mm"
                + (f"; {camera.padded_replies} replies came in full 0x200-byte buffers" if camera.padded_replies
                   else ""))
    try:
        if _try(lines, "open camera (interface 0) and read calibration", open_camera) is not None:
            _try(lines, "read register 0x06 (depth stream)", lambda: f"{camera.read_register(P.REG_DEPTH_STREAM):#x}")

            def write_off():
                camera.write_register(P.REG_DEPTH_STREAM, 0)
                odd = camera.odd_write_acks
                return f"answered {odd[-1][1]} instead of 0000 (accepted)" if odd else "acknowledged 0000"
            _try(lines, "write register 0x06 = 0 (depth off)", write_off)
    finally:
        camera.close()


def _stream_lines(info, backend, lines: list[str], seconds: float) -> None:
    stream = DepthStream(backend, serial=info.serial, queue_size=4).start()
    deadline = time.monotonic() + seconds
    messages = []
    while time.monotonic() < deadline and stream.status.state != ERROR:
        message = stream.status.message
        if not messages or messages[-1] != message:
            messages.append(message)
        if stream.status.frames >= 30:
            break
        time.sleep(0.02)
    status = stream.status
    if not messages or messages[-1] != status.message:
        messages.append(status.message)
    stream.stop(timeout=3.0)
    lines.append(f"    depth stream for up to {seconds:g} s: {status.frames} frames ({status.fps:.1f} fps), "
                 f"{status.packets_lost} packets lost, {status.frames_dropped} frames dropped, "
                 f"{status.reconnects} reconnects; state {status.state}")
    lines += [f"      status: {m}" for m in messages]


def diagnose(backend=None, stream_seconds: float = STREAM_TRY_S) -> str:
    """The whole report as text (for `devices --diagnose`)."""
    lines = [f"kinect_retarget devices --diagnose ({platform.platform()}, Python {sys.version.split()[0]}, "
             f"pyusb {usb.__version__})"]
    try:
        backend = backend or find_backend()
    except KinectError as exc:
        return "\n".join(lines + [f"libusb: {exc}"])
    lines.append(_libusb_line(backend))
    lines += _bus_lines(backend)
    kinects = list_devices(backend)
    if not kinects:
        lines.append(f"no Kinect v1 camera (045e:02ae or 045e:02bf) found: {nothing_found_reason(backend)}")
    for info in kinects:
        lines.append(f"{info.model}  serial {info.serial}  camera bus {info.bus} address {info.address}")
        for role in ("motor", "audio"):
            dev = getattr(info, role)
            found = f"{dev.idProduct:04x} on bus {dev.bus} address {dev.address}" if dev is not None else "none"
            lines.append(f"    {role} device: {found} ({info.matched.get(role, 'not looked for')})")
        lines.append(f"    camera: {'opens' if info.camera_available else 'not usable: ' + info.problem}")
        lines.append(f"    motor: {'ready' if info.motor_available else 'not available: ' + info.motor_note}")
        if not P.is_model_1414(info.camera.idProduct, info.camera.bcdDevice):
            _try(lines, "LED keep-alive to the audio chip", lambda: send_keep_alive(info.audio) or "sent, answered")
        if info.camera_available:
            _camera_lines(info, lines)
            _stream_lines(info, backend, lines, stream_seconds)
    return "\n".join(lines)
