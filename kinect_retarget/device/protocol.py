"""Kinect v1 wire protocol: USB ids, the GM/RB camera command format, register sequences, iso packet headers.

Pure bytes in, bytes out: no USB I/O here (kinect_camera.py does that), so the same code serves the real device, the
emulated one and offline dump replay. Facts follow libfreenect's protocol notes (docs/usb_driver.md).
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

from .errors import ProtocolError

# --- USB identifiers -------------------------------------------------------------------------------------
VENDOR_MICROSOFT = 0x045E
PID_CAMERA = 0x02AE           # Xbox 360 Kinect (models 1414 and 1473)
PID_CAMERA_K4W = 0x02BF       # Kinect for Windows
PID_MOTOR = 0x02B0            # model 1414 only
PID_MOTOR_K4W = 0x02C2
PID_AUDIO = 0x02AD
PID_AUDIO_K4W = 0x02BE
PID_AUDIO_K4W_SDK = 0x02C3    # Kinect for Windows audio once the SDK's firmware runs on it
PID_AUDIO_K4W_BETA = 0x02BB   # ... once the beta SDK's firmware runs on it
CAMERA_PIDS = (PID_CAMERA, PID_CAMERA_K4W)
MOTOR_PIDS = (PID_MOTOR, PID_MOTOR_K4W)
AUDIO_PIDS = (PID_AUDIO, PID_AUDIO_K4W, PID_AUDIO_K4W_SDK, PID_AUDIO_K4W_BETA)
BCD_MODEL_1414 = 267          # the 1414 camera reports bcdDevice 0x010B

CAMERA_INTERFACE = 0
DEPTH_ENDPOINT = 0x82
VIDEO_ENDPOINT = 0x81


def camera_model(product_id: int, bcd_device: int) -> str:
    """Human-readable model of a camera device."""
    if product_id == PID_CAMERA_K4W:
        return "Kinect for Windows"
    if product_id == PID_CAMERA and bcd_device == BCD_MODEL_1414:
        return "Xbox 360 Kinect (1414)"
    if product_id == PID_CAMERA:
        return "Xbox 360 Kinect (1473)"
    return f"unknown camera {product_id:#06x}"


def is_model_1414(product_id: int, bcd_device: int) -> bool:
    """Only the 1414 has a separate motor device; the others route motor and LED through the audio chip."""
    return product_id == PID_CAMERA and bcd_device == BCD_MODEL_1414


# --- camera command channel ("GM" out, "RB" back) ---------------------------------------------------------
CMD_REQUEST_OUT = 0x40        # vendor, device, host->device
CMD_REQUEST_IN = 0xC0         # vendor, device, device->host
CMD_REPLY_LENGTH = 0x200
CMD_MAX_PAYLOAD = 0x400 - 8

OP_READ_REGISTER = 0x02
OP_WRITE_REGISTER = 0x03
OP_FIXED_PARAMS = 0x04
OP_ALGORITHM_PARAMS = 0x16
ALGO_CONST_SHIFT = 0x00

MAGIC_COMMAND = b"GM"
MAGIC_REPLY = b"RB"
_HEADER = struct.Struct("<2sHHH")      # magic, payload length in 16-bit words, opcode, tag
HEADER_SIZE = _HEADER.size


@dataclass(frozen=True)
class CommandHeader:
    magic: bytes
    words: int
    opcode: int
    tag: int


def build_command(opcode: int, tag: int, payload: bytes = b"") -> bytes:
    """One GM command: 8-byte little-endian header, then the payload (an even number of bytes)."""
    if len(payload) % 2:
        raise ValueError(f"command payload must be whole 16-bit words, got {len(payload)} bytes")
    if len(payload) > CMD_MAX_PAYLOAD:
        raise ValueError(f"command payload of {len(payload)} bytes exceeds {CMD_MAX_PAYLOAD}")
    return _HEADER.pack(MAGIC_COMMAND, len(payload) // 2, opcode & 0xFFFF, tag & 0xFFFF) + payload


def parse_header(data: bytes) -> CommandHeader:
    if len(data) < HEADER_SIZE:
        raise ProtocolError(f"message of {len(data)} bytes is shorter than the 8-byte header")
    magic, words, opcode, tag = _HEADER.unpack_from(data)
    return CommandHeader(magic, words, opcode, tag)


def parse_reply(reply: bytes, opcode: int, tag: int) -> bytes:
    """Validate an RB reply to (opcode, tag) and return its payload."""
    hdr = parse_header(reply)
    if hdr.magic != MAGIC_REPLY:
        raise ProtocolError(f"reply magic {hdr.magic!r} is not 'RB'")
    if hdr.opcode != opcode:
        raise ProtocolError(f"reply is for opcode {hdr.opcode:#x}, expected {opcode:#x}")
    if hdr.tag != tag:
        raise ProtocolError(f"reply tag {hdr.tag} does not echo command tag {tag}")
    if hdr.words * 2 != len(reply) - HEADER_SIZE:
        raise ProtocolError(f"reply header announces {hdr.words * 2} payload bytes, "
                            f"got {len(reply) - HEADER_SIZE}")
    return bytes(reply[HEADER_SIZE:])


def words(*values: int) -> bytes:
    return struct.pack(f"<{len(values)}H", *values)


def write_register_command(reg: int, value: int, tag: int) -> bytes:
    return build_command(OP_WRITE_REGISTER, tag, words(reg, value))


# Register writes that start the 640x480 11-bit depth stream at 30 fps (after the iso transfers are queued).
REG_PROJECTOR_CYCLE = 0x105
REG_DEPTH_STREAM = 0x06
REG_DEPTH_FORMAT = 0x12
REG_DEPTH_RESOLUTION = 0x13
REG_DEPTH_FPS = 0x14
REG_DEPTH_FLIP = 0x17
DEPTH_START_SEQUENCE: tuple[tuple[int, int], ...] = (
    (REG_PROJECTOR_CYCLE, 0x00),   # projector auto-cycle off
    (REG_DEPTH_STREAM, 0x00),      # reset the depth stream
    (REG_DEPTH_FORMAT, 0x03),      # 11-bit packed
    (REG_DEPTH_RESOLUTION, 0x01),  # 640x480
    (REG_DEPTH_FPS, 0x1E),         # 30 fps
    (REG_DEPTH_STREAM, 0x02),      # start
    (REG_DEPTH_FLIP, 0x00),        # no horizontal flip: images stay as the camera sees them
)
DEPTH_STOP_SEQUENCE: tuple[tuple[int, int], ...] = ((REG_DEPTH_STREAM, 0x00),)

# --- isochronous depth packets ------------------------------------------------------------------------------
PACKET_HEADER_SIZE = 12
MAX_ISO_PACKET_SIZE = 1920             # 2 x 960-byte transactions per microframe
FLAG_DEPTH_SOF = 0x71
FLAG_DEPTH_MOF = 0x72
FLAG_DEPTH_EOF = 0x75
DEPTH_WIDTH, DEPTH_HEIGHT = 640, 480
DEPTH_FRAME_BYTES = DEPTH_WIDTH * DEPTH_HEIGHT * 11 // 8     # 422,400
DEPTH_PAYLOAD = 1748                   # per packet, 1760 with the header
DEPTH_PACKETS_PER_FRAME = -(-DEPTH_FRAME_BYTES // DEPTH_PAYLOAD)   # 242
DEPTH_LAST_PAYLOAD = DEPTH_FRAME_BYTES - DEPTH_PAYLOAD * (DEPTH_PACKETS_PER_FRAME - 1)   # 1132
TIMESTAMP_HZ = 60_000_000
TIMESTAMP_WRAP = 1 << 32   # the frame timestamp is a 32-bit counter
TICKS_PER_FRAME = TIMESTAMP_HZ // 30
_PACKET = struct.Struct("<2sBBBB")     # magic, pad, flag, unknown, seq; then length (BE) and timestamp (LE)


@dataclass(frozen=True)
class PacketHeader:
    flag: int
    seq: int
    length: int        # total length announced by the device, header included
    timestamp: int     # 60 MHz ticks, wraps at 2**32


def parse_packet_header(packet: bytes) -> PacketHeader | None:
    """Header of one iso packet, or None when it is too short or lacks the 'RB' magic."""
    if len(packet) < PACKET_HEADER_SIZE or packet[0] != 0x52 or packet[1] != 0x42:
        return None
    return PacketHeader(packet[3], packet[5], (packet[6] << 8) | packet[7],
                        int.from_bytes(packet[8:12], "little"))


def build_packet_header(flag: int, seq: int, length: int, timestamp: int) -> bytes:
    return (_PACKET.pack(MAGIC_REPLY, 0, flag, 0, seq & 0xFF) + (length & 0xFFFF).to_bytes(2, "big")
            + wrap_ticks(timestamp).to_bytes(4, "little"))


def depth_packet_flag(index_in_frame: int) -> int:
    if index_in_frame == 0:
        return FLAG_DEPTH_SOF
    if index_in_frame == DEPTH_PACKETS_PER_FRAME - 1:
        return FLAG_DEPTH_EOF
    return FLAG_DEPTH_MOF


# --- the device clock: a 32-bit counter of 60 MHz ticks. These three are the only places it wraps. ---------
def wrap_ticks(ticks):
    """A tick count (int or array) as the device's 32-bit clock shows it: modulo 2**32, never negative."""
    return ticks % TIMESTAMP_WRAP


def advance_ticks(stamp, ticks):
    """The clock reading `ticks` after `stamp` (ints or arrays), wrapping past 2**32."""
    return wrap_ticks(stamp + ticks)


def ticks_between(earlier, later):
    """Device clock ticks from `earlier` to `later` (ints or arrays): the 32-bit counter wraps, so a later
    stamp may be smaller. The one place the wrap is undone (capture files, live depth, reassembly, the CLI)."""
    return wrap_ticks(later - earlier)
