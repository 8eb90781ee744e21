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
                       "its proprietary firmware (audios.bin) has been uploaded to it. That file is not included "
                       "and may not be redistributed: libfreenect's src/fwfetcher.py extracts it from a "
                       "Microsoft Xbox 360 system update. Put it in ~/.libfreenect/ (or the folder named by "
                       "LIBFREENECT_FIRMWARE_PATH) and the tilt, led and accel commands upload it themselves, as "
                       "libfreenect does; it stays until the Kinect loses power. Depth streaming works without it.")


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
    audio: object = field(default=None, repr=False)    # usb.core.Device of the audio chip, if found
    matched: dict = field(default_factory=dict)        # how motor and audio were paired with the camera

    @property
    def needs_audio_firmware(self) -> bool:
        """The motor goes through an audio chip that is reachable but still in its bootloader."""
        return not self.motor_available and self.motor_note == MOTOR_FIRMWARE_NOTE

    def describe(self) -> str:
        lines = [f"{self.model}  serial {self.serial}  (bus {self.bus}, address {self.address})",
                 f"  camera: {'ready' if self.camera_available else 'not usable'}",
                 f"  motor:  {'ready' if self.motor_available else 'not available'}"
                 + (f" - {self.motor_note}" if self.motor_note else "")]
        if self.problem:
            lines.append(f"  problem: {self.problem}")
        return "\n".join(lines)


def _parent(dev) -> tuple | None:
    """The hub port a device hangs off (bus, port path minus its own port), None where the OS won't say."""
    ports = getattr(dev, "port_numbers", None)
    return (dev.bus, tuple(ports[:-1])) if ports else None


def find_sibling(camera, devices, product_ids) -> tuple[object | None, str]:
    """The motor or audio device that belongs to `camera`, as libfreenect pairs them: the one behind the same
    hub, else the only one on the camera's bus, else the only one on the system (an xHCI port, or an OS that
    reports no port path, still gives one Kinect). Returns (device or None, how it was matched)."""
    candidates = [d for d in devices if d.idProduct in product_ids]
    parent = _parent(camera)
    if parent is not None:
        for d in candidates:
            if _parent(d) == parent:
                return d, "same hub"
    same_bus = [d for d in candidates if d.bus == camera.bus]
    if len(same_bus) == 1:
        return same_bus[0], "only one on the bus"
    if len(candidates) == 1:
        return candidates[0], "only one on the system"
    return None, f"{len(candidates)} candidates, none behind the camera's hub" if candidates else "none found"


def _read_serial(dev, role: str = "camera") -> tuple[str | None, str]:
    """(serial, problem): opening the device to read its serial string also tests access."""
    try:
        try:
            serial = usb.util.get_string(dev, dev.iSerialNumber) if dev.iSerialNumber else ""
            return serial or "", ""
        except ValueError:
            # pyusb hides why it could not read the language ids ("permission issue, ... or device error"):
            # opening the device again gives the real error
            dev._ctx.managed_open()
            return None, f"the {role} answers no string descriptors (a device error): unplug and replug it"
    except (usb.core.USBError, NotImplementedError) as exc:
        if isinstance(exc, usb.core.USBError) and is_gone(exc):
            return None, "the device disappeared while it was being read"
        return None, access_advice(exc, role)
    finally:
        usb.util.dispose_resources(dev)


def audio_motor_state(audio) -> tuple[bool, str]:
    """(motor usable, note) for a model whose motor and LED go through the audio chip: its firmware must run
    (two or more interfaces). A device that cannot even be read is reported as that, not as no firmware."""
    if audio is None:
        return False, "the audio device (which carries the motor on this model) was not found on the bus"
    try:
        if audio.get_active_configuration().bNumInterfaces >= 2:
            return True, ""
    except usb.core.USBError as exc:
        if is_gone(exc):
            return False, "the audio device disappeared while it was being read"
        return False, f"the audio device (which carries the motor) cannot be read: {access_advice(exc, 'audio')}"
    except NotImplementedError as exc:
        return False, f"the audio device (which carries the motor) cannot be read: {access_advice(exc, 'audio')}"
    finally:
        usb.util.dispose_resources(audio)
    return False, MOTOR_FIRMWARE_NOTE


def list_devices(backend=None) -> list[KinectInfo]:
    """Every Kinect v1 camera on the bus, with what can be used and, if not, why and how to fix it.

    backend: a pyusb backend (e.g. an EmulatedKinect); default: pyusb's libusb1 backend.
    Raises LibusbMissing (with advice) when no libusb can be loaded.
    """
    backend = backend or find_backend()
    devices = list(usb.core.find(find_all=True, idVendor=P.VENDOR_MICROSOFT, backend=backend))
    cameras = [d for d in devices if d.idProduct in P.CAMERA_PIDS]
    found = []
    for cam in cameras:
        serial, problem = _read_serial(cam)
        audio, audio_match = find_sibling(cam, devices, P.AUDIO_PIDS)
        if (serial is None or set(serial) <= {"0"}) and audio is not None:
            # 1473 / Kinect for Windows cameras report sixteen zeros: the audio device has the real serial
            audio_serial, _ = _read_serial(audio, "audio")
            serial = audio_serial or serial
        if P.is_model_1414(cam.idProduct, cam.bcdDevice):
            motor, motor_match = find_sibling(cam, devices, P.MOTOR_PIDS)
            motor_ok, note = motor is not None, "" if motor is not None else "motor device not found on the bus"
        else:
            motor, motor_match = audio, audio_match
            motor_ok, note = audio_motor_state(audio)
        found.append(KinectInfo(model=P.camera_model(cam.idProduct, cam.bcdDevice), serial=serial or "?",
                                bus=cam.bus, address=cam.address, camera_available=not problem,
                                motor_available=motor_ok, motor_note=note, problem=problem,
                                camera=cam, motor=motor, audio=audio,
                                matched={"motor": motor_match, "audio": audio_match}))
    return found


KINECT_V2_PIDS = (0x02D8, 0x02D9, 0x02C4)


def nothing_found_reason(backend) -> str:
    """Why no Kinect camera was found, from what else of Microsoft's is on the bus."""
    try:
        others = {d.idProduct for d in usb.core.find(find_all=True, idVendor=P.VENDOR_MICROSOFT,
                                                     backend=backend or find_backend())}
    except (usb.core.USBError, NotImplementedError):
        others = set()
    if others & set(KINECT_V2_PIDS):
        return ("no Kinect v1 found, but a Kinect v2 (Xbox One / Kinect for Windows v2) is plugged in: it is a "
                "different device (USB 3, another protocol) that this driver does not support (libfreenect2 does)")
    if others & set(P.MOTOR_PIDS + P.AUDIO_PIDS):
        return ("the Kinect's motor or audio device is on the bus but not its camera: check that its own 12 V "
                "power adapter is plugged in; on Windows the camera may also appear only once the motor "
                "device has a driver (Zadig: 'Xbox NUI Motor', USB ID 045E 02B0)")
    return ("no Kinect found: check that it is plugged in and powered by its own adapter "
            "(a v1 Kinect needs the external 12 V supply)")


def find_kinect(backend=None, serial: str | None = None) -> KinectInfo:
    """The Kinect with this serial (or the first one); DeviceNotFound says what was seen instead."""
    kinects = list_devices(backend)
    for info in kinects:
        if serial is None or info.serial == serial:
            return info
    if not kinects:
        raise DeviceNotFound(nothing_found_reason(backend))
    raise DeviceNotFound(f"no Kinect with serial {serial}; found {', '.join(k.serial for k in kinects)}")


__all__ = ["KinectInfo", "list_devices", "find_kinect", "UDEV_RULES", "udev_rule_install_command",
           "LibusbMissing"]
