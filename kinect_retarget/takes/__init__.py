"""Take readers. `load_take(path)` detects the format from the file's content, not its extension.

Each reader module offers `looks_like(head: bytes) -> bool` (the first 4 KiB of the file) and
`read(path) -> Take`; every problem raises TakeError naming the file and line.
"""
from __future__ import annotations

import os
from importlib import import_module

from ..core.take import Take, TakeError

# Tried in order: the most specific signatures first.
READERS = ("krtake", "kinectron_json", "bvh", "kinect_v2_csv", "uiprmd", "msrc12", "utkinect", "ntu_skeleton")


def detect_format(path: str | os.PathLike) -> str:
    path = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except OSError as exc:
        raise TakeError(f"{path}: cannot open take ({exc.strerror})") from None
    if not head.strip():
        raise TakeError(f"{path}: file is empty")
    for name in READERS:
        if import_module(f".{name}", __name__).looks_like(head):
            return name
    raise TakeError(f"{path}: unknown take format (supported: {', '.join(READERS)})")


def load_take(path: str | os.PathLike, scale: float | None = None) -> Take:
    """`scale`: metres per file unit, for BVH files (other formats are in metres already)."""
    fmt = detect_format(path)
    if scale is None:
        return import_module(f".{fmt}", __name__).read(path)
    if fmt != "bvh":
        raise TakeError(f"{os.fspath(path)}: scale applies to BVH files only ({fmt} takes are in metres already)")
    return import_module(f".{fmt}", __name__).read(path, scale=scale)


__all__ = ["load_take", "detect_format", "Take", "TakeError", "READERS"]
