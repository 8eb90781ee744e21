"""The audio chip's firmware (audios.bin) on models 1473 and Kinect for Windows: find it, upload it, wait.

Their tilt motor, LED and accelerometer answer only once the audio chip runs this firmware; the depth camera
never needs it. The file is Microsoft's and is not shipped: libfreenect's src/fwfetcher.py extracts it from
an Xbox 360 system update. Like libfreenect we look for it in $LIBFREENECT_FIRMWARE_PATH, the current folder,
~/.libfreenect, /usr/local/share/libfreenect and /usr/share/libfreenect, and upload it to the chip's
bootloader over bulk endpoint 0x01 (0x4000-byte pages in 512-byte writes, each answered on 0x81), then tell
it to run; the chip then leaves the bus and comes back with its firmware running (two or more interfaces).
"""
from __future__ import annotations

import os
import struct
import time
from dataclasses import dataclass
from pathlib import Path

import usb.core
import usb.util

from .errors import BadInputFile, KinectError, ProtocolError

FIRMWARE_FILE = "audios.bin"
AUDIOS_MAGIC = 0xCA77F00D            # the audio firmware's header magic (the second-stage loader has another)
BOOT_MAGIC, BOOT_REPLY_MAGIC = 0x06022009, 0x0A6FE000
BOOT_WRITE, BOOT_RUN = 0x03, 0x04
PAGE = 0x4000
CHUNK = 512
_HEADER = struct.Struct("<I4H3I")    # magic, version minor/major/release/patch, base address, size, entry point
REENUMERATE_WAIT_S = 10.0            # libfreenect: 10 tries a second apart


@dataclass(frozen=True)
class FirmwareImage:
    path: str
    version: str
    base: int
    entry: int
    data: bytes          # the bytes uploaded from `base` on: the file's first `size` bytes, header included


def firmware_paths(env=None) -> list[Path]:
    """Where audios.bin is looked for, in order (libfreenect's list)."""
    env = os.environ if env is None else env
    folders = ([Path(env["LIBFREENECT_FIRMWARE_PATH"])] if env.get("LIBFREENECT_FIRMWARE_PATH") else []) + [Path(".")]
    if env.get("HOME"):
        folders.append(Path(env["HOME"]) / ".libfreenect")
    folders += [Path("/usr/local/share/libfreenect"), Path("/usr/share/libfreenect")]
    return [folder / FIRMWARE_FILE for folder in folders]


def find_firmware(env=None) -> Path | None:
    return next((p for p in firmware_paths(env) if p.is_file()), None)


def read_firmware(path) -> FirmwareImage:
    """The image in an audios.bin file; BadInputFile (naming the file) when it is not one."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise BadInputFile(f"{path}: cannot read the audio firmware ({exc})") from exc
    if len(data) < _HEADER.size:
        raise BadInputFile(f"{path}: {len(data)} bytes is too short for an audio firmware image")
    magic, minor, major, release, patch, base, size, entry = _HEADER.unpack_from(data)
    if magic != AUDIOS_MAGIC:
        raise BadInputFile(f"{path}: not the Kinect audio firmware (header magic {magic:#010x}, expected "
                           f"{AUDIOS_MAGIC:#010x}); use the audios.bin that libfreenect's fwfetcher.py extracts")
    if size > len(data) or size == 0:
        raise BadInputFile(f"{path}: the header announces {size} bytes but the file holds {len(data)}")
    return FirmwareImage(str(path), f"{major}.{minor}.{release}.{patch}", base, entry, data[:size])


class _Bootloader:
    def __init__(self, audio):
        self.audio = audio
        self.tag = 0

    def command(self, cmd: int, addr: int, payload: bytes = b"") -> None:
        self.audio.write(0x01, struct.pack("<6I", BOOT_MAGIC, self.tag, len(payload), cmd, addr, 0), 1000)
        for start in range(0, len(payload), CHUNK):
            self.audio.write(0x01, payload[start:start + CHUNK], 1000)
        reply = bytes(self.audio.read(0x81, 512, 1000))
        if len(reply) != 12:
            raise ProtocolError(f"audio bootloader reply has {len(reply)} bytes, expected 12")
        magic, tag, status = struct.unpack("<3I", reply)
        if magic != BOOT_REPLY_MAGIC or tag != self.tag or status != 0:
            raise ProtocolError(f"audio bootloader refused command {cmd} at {addr:#x} "
                                f"(magic {magic:#x}, tag {tag}, status {status})")
        self.tag += 1


def upload_firmware(audio, image: FirmwareImage) -> None:
    """Send the image to the audio chip's bootloader and start it. The chip then re-enumerates."""
    usb.util.claim_interface(audio, 0)
    try:
        boot = _Bootloader(audio)
        for offset in range(0, len(image.data), PAGE):
            boot.command(BOOT_WRITE, image.base + offset, image.data[offset:offset + PAGE])
        boot.command(BOOT_RUN, image.entry)
    finally:
        usb.util.dispose_resources(audio)


def boot_audio_chip(info, find, path=None, wait_s: float = REENUMERATE_WAIT_S, sleep=time.sleep):
    """Upload audios.bin to this Kinect's audio chip and return its KinectInfo once the firmware runs.

    info: the KinectInfo (its audio device in the bootloader); find(serial) -> KinectInfo (discovery again).
    Raises KinectError saying what failed: no file, a bad file, a refused upload, no re-enumeration."""
    path = path or find_firmware()
    if path is None:
        raise KinectError("the audio firmware audios.bin was not found (looked in "
                          + ", ".join(str(p.parent) for p in firmware_paths()) + ")")
    image = read_firmware(path)
    try:
        upload_firmware(info.audio, image)
    except usb.core.USBError as exc:
        raise KinectError(f"uploading {path} to the Kinect's audio chip failed: {exc}") from exc
    deadline = time.monotonic() + wait_s
    while True:
        try:
            again = find(info.serial)
            if again.motor_available:
                return again
        except KinectError:
            pass                                  # still off the bus
        if time.monotonic() > deadline:
            raise KinectError(f"uploaded {path} (version {image.version}), but the audio chip did not come back "
                              f"with its firmware running within {wait_s:g} s: unplug and replug the Kinect")
        sleep(0.25)
