"""OSC 1.0 packets, decoded strictly: messages and bundles with numeric arguments (i, f, d, h) and strings.

Nothing in a packet is ever evaluated; anything malformed raises OscError naming the problem.
"""
from __future__ import annotations

import struct

BUNDLE_TAG = b"#bundle\x00"
_NUMERIC = {"i": (">i", 4), "f": (">f", 4), "d": (">d", 8), "h": (">q", 8)}


class OscError(ValueError):
    pass


def _read_string(data: bytes, pos: int) -> tuple[str, int]:
    end = data.find(b"\x00", pos)
    if end < 0:
        raise OscError(f"unterminated string at byte {pos}")
    try:
        text = data[pos:end].decode("ascii")
    except UnicodeDecodeError:
        raise OscError(f"non-ASCII string at byte {pos}") from None
    return text, (end + 4) & ~3  # strings are NUL-terminated and padded to 4 bytes


def parse_message(data: bytes) -> tuple[str, list]:
    address, pos = _read_string(data, 0)
    if not address.startswith("/"):
        raise OscError(f"address {address[:40]!r} does not start with '/'")
    if pos >= len(data):
        return address, []  # OSC 1.0 allows a missing type tag string
    tags, pos = _read_string(data, pos)
    if not tags.startswith(","):
        raise OscError(f"type tags of {address} do not start with ','")
    args: list = []
    for tag in tags[1:]:
        if tag in _NUMERIC:
            fmt, size = _NUMERIC[tag]
            if pos + size > len(data):
                raise OscError(f"{address}: packet ends inside argument {len(args) + 1}")
            args.append(struct.unpack_from(fmt, data, pos)[0])
            pos += size
        elif tag == "s":
            text, pos = _read_string(data, pos)
            args.append(text)
        elif tag in "TF":
            args.append(tag == "T")
        else:
            raise OscError(f"{address}: unsupported OSC argument type {tag!r}")
    if pos > len(data):
        raise OscError(f"{address}: packet ends inside its arguments")
    return address, args


def parse_packet(data: bytes, depth: int = 0) -> list[tuple[str, list]]:
    """All messages of a packet in order (bundles are flattened)."""
    if not data or len(data) % 4:
        raise OscError(f"packet of {len(data)} bytes is not a multiple of 4")
    if not data.startswith(BUNDLE_TAG):
        return [parse_message(data)]
    if depth > 8:
        raise OscError("bundles nested too deeply")
    out: list[tuple[str, list]] = []
    pos = 16  # tag + 8-byte time tag
    while pos < len(data):
        if pos + 4 > len(data):
            raise OscError("bundle element size is truncated")
        (size,) = struct.unpack_from(">i", data, pos)
        pos += 4
        if size <= 0 or pos + size > len(data):
            raise OscError(f"bundle element of {size} bytes overruns the packet")
        out.extend(parse_packet(data[pos:pos + size], depth + 1))
        pos += size
    return out


def _pad(b: bytes) -> bytes:
    return b + b"\x00" * (4 - len(b) % 4)


def encode_message(address: str, *args) -> bytes:
    """For tests, benchmarks and bridges: floats as 'f', ints as 'i', str as 's'."""
    tags, payload = ",", b""
    for a in args:
        if isinstance(a, str):
            tags, payload = tags + "s", payload + _pad(a.encode("ascii"))
        elif isinstance(a, int) and not isinstance(a, bool):
            tags, payload = tags + "i", payload + struct.pack(">i", a)
        else:
            tags, payload = tags + "f", payload + struct.pack(">f", float(a))
    return _pad(address.encode("ascii")) + _pad(tags.encode("ascii")) + payload


def encode_bundle(messages: list[bytes]) -> bytes:
    return BUNDLE_TAG + b"\x00" * 7 + b"\x01" + b"".join(struct.pack(">i", len(m)) + m for m in messages)
