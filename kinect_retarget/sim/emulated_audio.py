"""The emulated Kinect's audio chip before its firmware runs: the bootloader of models 1473 and Kinect for
Windows. It takes libfreenect's LED keep-alive (routed to emulated_motor.py by the caller) and a firmware
upload: 24-byte commands {0x06022009, tag, bytes, cmd, address, 0} on bulk endpoint 0x01 (3: write the
`bytes` that follow at `address`; 4: run from `address`; 0: version), each answered {0x0A6FE000, tag, status}
on 0x81. Once told to run a well-formed audios image, the chip re-enumerates with its firmware running.
"""
from __future__ import annotations

import struct

BOOT_MAGIC, REPLY_MAGIC, AUDIOS_MAGIC = 0x06022009, 0x0A6FE000, 0xCA77F00D
_COMMAND = struct.Struct("<6I")
_IMAGE_HEADER = struct.Struct("<I4H3I")   # magic, version x4, base address, size, entry point
MAX_PAGE = 0x4000


def _status(tag: int, status: int) -> bytes:
    return struct.pack("<3I", REPLY_MAGIC, tag, status)


class AudioBootloader:
    def __init__(self):
        self.memory: dict[int, bytes] = {}   # address -> page written there
        self._page: tuple[int, int, bytearray, int] | None = None   # address, expected bytes, received, tag
        self.booted = False                  # told to run a valid image: the chip re-enumerates

    def command(self, data: bytes) -> list[bytes] | None:
        """Replies for one bulk write; None when it is not a bootloader command (the LED keep-alive)."""
        if self._page is not None:
            address, expected, received, tag = self._page
            received += data
            if len(received) < expected:
                return []
            self._page = None
            if len(received) > expected:
                return [_status(tag, 4)]
            self.memory[address] = bytes(received)
            return [_status(tag, 0)]
        if len(data) != _COMMAND.size:
            return None
        magic, tag, nbytes, cmd, address, _ = _COMMAND.unpack(data)
        if magic != BOOT_MAGIC:
            return [_status(tag, 1)]
        if cmd == 0:
            return [bytes(0x60), _status(tag, 0)]
        if cmd == 3 and 0 < nbytes <= MAX_PAGE:
            self._page = (address, nbytes, bytearray(), tag)
            return []
        if cmd == 4 and self._valid_image(address):
            self.booted = True
            return [_status(tag, 0)]
        return [_status(tag, 3)]

    def _valid_image(self, entry: int) -> bool:
        """The pages form one image from its base address, whose header announces this size and entry."""
        if not self.memory:
            return False
        base = min(self.memory)
        image, address = bytearray(), base
        while address in self.memory:
            image += self.memory[address]
            address += len(self.memory[address])
        if len(image) < _IMAGE_HEADER.size:
            return False
        magic, *_version, head_base, size, head_entry = _IMAGE_HEADER.unpack_from(image)
        return magic == AUDIOS_MAGIC and head_base == base and size == len(image) and head_entry == entry
