"""Finding Kinects on the USB bus, and saying plainly why one cannot be used.

A Kinect v1 shows up as several USB devices behind its internal hub: camera, audio and (model 1414) motor.
They are grouped by bus and hub port path.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import usb.core
import usb.util

from . import protocol as P
from .kinect_camera import access_advice, is_gone
from .errors import DeviceNotFound, LibusbMissing
from .usb_backend import find_backend

UDEV_RULES_PATH = "/etc/udev/rules.d/51-kinect.rules"
UDEV_RULES = "\n".join(
    f'SUBSYSTEM=="usb", ATTR{{idVendor}}=="045e", ATTR{{idProduct}}=="{pid:04x}", MODE="0666"'
    for pid in (*P.MOTOR_PIDS, *P.AUDIO_PIDS, *P.CAMERA_PIDS)) + "\n"


def udev_rule_install_command() -> str:
    return (f"printf '%s' '{UDEV_RULES}' | sudo tee {UDEV_RULES_PATH} && "
            "sudo udevadm control --reload-rules && sudo udevadm trigger")


MOTOR_FIRMWARE_NOTE = ("tilt, LED and accelerometer on this model go through the audio chip and only work after "
                       "its proprietary firmware is uploaded (e.g. by the Kinect SDK or libfreenect's "
                       "fwfetcher); it is not included. Depth streaming works without it.")


@dataclass
class KinectInfo:
    """One Kinect as found on the bus."""
    model: str
    serial: str
    bus: int | None
    address: int | None
    camera_available: bool
    motor_available: bool
    motor_note: str = ""
    problem: str = ""                 # why the camera cannot be opened, with the fix
    camera: object = field(default=None, repr=False)   # usb.core.Device
    motor: object = field(default=None, repr=False)    # usb.core.Device (1414) or audio device (others)

    def describe(self) -> str:
        lines = [f"{self.model}  serial {self.serial}  (bus {self.bus}, address {self.address})",
                 f"  camera: {'ready' if self.camera_available else 'not usable'}",
                 f"  motor:  {'ready' if self.motor_available else 'not available'}"
                 + (f" - {self.motor_note}" if self.motor_note else "")]
        if self.problem:
            lines.append(f"  problem: {self.problem}")
        return "\n".join(lines)


def _hub_key(dev) -> tuple:
    ports = getattr(dev, "port_numbers", None)
    return (dev.bus, tuple(ports[:-1]) if ports else None)


def _read_serial(dev) -> tuple[str | None, str]:
    """(serial, problem): opening the device to read its serial string also tests access."""
    try:
        serial = usb.util.get_string(dev, dev.iSerialNumber) if dev.iSerialNumber else ""
        return serial or "", ""
    except (usb.core.USBError, NotImplementedError, ValueError) as exc:
        if isinstance(exc, usb.core.USBError) and is_gone(exc):
            return None, "the device disappeared while it was being read"
        return None, access_advice(exc)
    finally:
        usb.util.dispose_resources(dev)


def _audio_firmware_running(audio) -> bool:
    try:
        return audio is not None and audio.get_active_configuration().bNumInterfaces >= 2
    except (usb.core.USBError, NotImplementedError):
        return False


def list_devices(backend=None) -> list[KinectInfo]:
    """Every Kinect v1 camera on the bus, with what can be used and, if not, why and how to fix it.

    backend: a pyusb backend (e.g. an EmulatedKinect); default: pyusb's libusb1 backend.
    Raises LibusbMissing (with advice) when no libusb can be loaded.
    """
    backend = backend or find_backend()
    devices = list(usb.core.find(find_all=True, idVendor=P.VENDOR_MICROSOFT, backend=backend))
    cameras = [d for d in devices if d.idProduct in P.CAMERA_PIDS]
    motors = {_hub_key(d): d for d in devices if d.idProduct in P.MOTOR_PIDS}
    audios = {_hub_key(d): d for d in devices if d.idProduct in P.AUDIO_PIDS}
    found = []
    for cam in cameras:
        key = _hub_key(cam)
        serial, problem = _read_serial(cam)
        audio = audios.get(key)
        if (serial is None or set(serial) <= {"0"}) and audio is not None:
            # 1473 / Kinect for Windows cameras report sixteen zeros: the audio device has the real serial
            audio_serial, _ = _read_serial(audio)
            serial = audio_serial or serial
        if P.is_model_1414(cam.idProduct, cam.bcdDevice):
            motor = motors.get(key)
            motor_ok, note = motor is not None, "" if key in motors else "motor device not found on the bus"
        else:
            motor = audio
            motor_ok = _audio_firmware_running(audio)
            note = "" if motor_ok else MOTOR_FIRMWARE_NOTE
        found.append(KinectInfo(model=P.camera_model(cam.idProduct, cam.bcdDevice), serial=serial or "?",
                                bus=cam.bus, address=cam.address, camera_available=not problem,
                                motor_available=motor_ok, motor_note=note, problem=problem,
                                camera=cam, motor=motor))
    return found


def find_kinect(backend=None, serial: str | None = None) -> KinectInfo:
    """The Kinect with this serial (or the first one); DeviceNotFound says what was seen instead."""
    kinects = list_devices(backend)
    for info in kinects:
        if serial is None or info.serial == serial:
            return info
    if not kinects:
        raise DeviceNotFound("no Kinect found: check that it is plugged in and powered by its own adapter "
                             "(a v1 Kinect needs the external 12 V supply)")
    raise DeviceNotFound(f"no Kinect with serial {serial}; found {', '.join(k.serial for k in kinects)}")


__all__ = ["KinectInfo", "list_devices", "find_kinect", "UDEV_RULES", "udev_rule_install_command",
           "LibusbMissing"]
