"""Packet dumps: every isochronous packet from endpoint 0x82 as received, for offline decoding and bug reports.

Format (docs/usb_driver.md): a sequence of records, each a little-endian uint32 length followed by that many
bytes of one packet, header included. A record of length 0 marks a packet the USB stack reported lost.
Empty microframes (no data, no error) are not recorded. There is no file header.
"""
from __future__ import annotations

import struct
from pathlib import Path

from .errors import DumpError
from .reassembly import AssembledFrame, FrameAssembler

_LEN = struct.Struct("<I")
MAX_RECORD = 1 << 16            # an iso packet is at most a few KB: anything larger means a corrupt file


class DumpWriter:
    """Appends packets to a dump file; safe to call from the streaming thread (the only writer)."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self._file = open(self.path, "wb")
        self.records = 0

    def write_packets(self, packets) -> None:
        parts = []
        for p in packets:
            if p is None:
                parts.append(_LEN.pack(0))
            elif len(p):
                parts.append(_LEN.pack(len(p)))
                parts.append(bytes(p))
            else:
                continue
            self.records += 1
        self._file.write(b"".join(parts))

    def close(self) -> None:
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def read_dump(path: str | Path):
    """Yield packets (bytes, or None for a lost one) in order; DumpError names the file, record and offset
    of a truncated or corrupt record, after everything before it has been yielded."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise DumpError(f"{path}: cannot read the dump ({exc.strerror or exc})") from exc
    view = memoryview(data)
    pos, record, end = 0, 0, len(data)
    while pos < end:
        if pos + 4 > end:
            raise DumpError(f"{path}: truncated at byte {pos} (record {record}): {end - pos} bytes left, "
                            "a record length needs 4")
        (n,) = _LEN.unpack_from(data, pos)
        if n > MAX_RECORD:
            raise DumpError(f"{path}: record {record} at byte {pos} claims {n} bytes; not a packet dump "
                            "or corrupt")
        if pos + 4 + n > end:
            raise DumpError(f"{path}: truncated at byte {pos} (record {record}): it needs {n} bytes, "
                            f"only {end - pos - 4} remain")
        yield bytes(view[pos + 4:pos + 4 + n]) if n else None
        pos += 4 + n
        record += 1


def replay_dump(path: str | Path) -> tuple[list[AssembledFrame], FrameAssembler, DumpError | None]:
    """Reassemble a dump through the live code path. Returns (frames, assembler with stats, error or None):
    a truncated dump still gives every frame completed before the damage. An unreadable file raises."""
    if not Path(path).is_file():
        raise DumpError(f"{path}: no such dump file")
    assembler = FrameAssembler()
    frames: list[AssembledFrame] = []
    batch: list = []
    try:
        for packet in read_dump(path):
            batch.append(packet)
            if len(batch) >= 256:
                frames += assembler.feed(batch)
                batch = []
    except DumpError as exc:
        frames += assembler.feed(batch)
        return frames, assembler, exc
    frames += assembler.feed(batch)
    return frames, assembler, None
