"""Take readers. `load_take(path)` detects the format from the file's content, not its extension.

Each reader module offers `looks_like(head: bytes) -> bool` (the first 4 KiB of the file) and
`read(path) -> Take`; every problem raises TakeError naming the file and line.
"""
from __future__ import annotations

import os

from ..core.take import Take, TakeError
from . import bvh, kinect_v2_csv, kinectron_json, krtake, msrc12, ntu_skeleton, uiprmd, utkinect

# Tried in order: the most specific signatures first. Imported statically, so a missing reader fails at import.
_READER_MODULES = (krtake, kinectron_json, bvh, kinect_v2_csv, uiprmd, msrc12, utkinect, ntu_skeleton)
READERS = tuple(module.__name__.rpartition(".")[2] for module in _READER_MODULES)   # format names, for messages
_READER_BY_NAME = dict(zip(READERS, _READER_MODULES))
# Formats whose files can hold several performers: their `read(path, body=N)` reads body N (from 0).
MULTI_BODY = ("kinectron_json", "ntu_skeleton")


def detect_format(path: str | os.PathLike) -> str:
    path = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except OSError as exc:
        raise TakeError(f"{path}: cannot open take ({exc.strerror})") from None
    if not head.strip():
        raise TakeError(f"{path}: file is empty")
    for name, reader in _READER_BY_NAME.items():
        if reader.looks_like(head):
            return name
    raise TakeError(f"{path}: unknown take format (supported: {', '.join(READERS)})")


def load_take(path: str | os.PathLike, scale: float | None = None, body: int = 0) -> Take:
    """`scale`: metres per file unit, for BVH files (other formats are in metres already). `body`: which
    performer of a take with several (NTU, Kinectron; numbered from 0); `metadata["bodies"]` says how many."""
    fmt = detect_format(path)
    reader = _READER_BY_NAME[fmt]
    if isinstance(body, bool) or not isinstance(body, int) or body < 0:
        raise TakeError(f"{os.fspath(path)}: body must be a whole number from 0, got {body!r}")
    if fmt in MULTI_BODY and scale is None:
        return reader.read(path, body=body)
    if body and fmt not in MULTI_BODY:
        raise TakeError(f"{os.fspath(path)}: {fmt} takes hold one body (body 0); body {body} was asked for")
    if scale is None:
        return reader.read(path)
    if fmt != "bvh":
        raise TakeError(f"{os.fspath(path)}: scale applies to BVH files only ({fmt} takes are in metres already)")
    return reader.read(path, scale=scale)


def body_count(take: Take) -> int:
    """How many performers the take's file holds (1 for formats with one)."""
    return int(take.metadata.get("bodies", 1)) or 1


__all__ = ["load_take", "detect_format", "body_count", "Take", "TakeError", "READERS", "MULTI_BODY"]
