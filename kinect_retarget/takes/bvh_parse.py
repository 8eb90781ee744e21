"""BVH text -> hierarchy and raw channel values, accepting the layouts real exporters write.

Accepted beyond the textbook layout: a root written `JOINT` instead of `ROOT`; end sites written `JOINT Site`
(with or without `CHANNELS 0`); `CHANNELS 0` on any joint; channel names in any case (`ZPosition`); any rotation
order per joint; tabs, CRLF, a UTF-8 byte order mark. Every problem raises TakeError naming the file and line.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..core.take import TakeError
from ._numeric import parse_table, read_bytes

_AXES = {"xposition": 0, "yposition": 1, "zposition": 2, "xrotation": 0, "yrotation": 1, "zrotation": 2}
_CANONICAL = {c: c[0].upper() + c[1:] for c in _AXES}  # 'zposition' -> 'Zposition'


def looks_like(head: bytes) -> bool:
    return head.lstrip(b"\xef\xbb\xbf \t\r\n").upper().startswith(b"HIERARCHY")


def channel_axis(channel: str) -> int:
    return _AXES[channel.lower()]


@dataclass
class BvhSkeleton:
    """The hierarchy. Joints are in file order, so every parent comes before its children."""

    names: tuple[str, ...]
    parents: np.ndarray          # (N,) int, -1 for the root
    offsets: np.ndarray          # (N, 3) file units, lab axes
    channels: tuple[tuple[str, ...], ...]  # per joint, e.g. ("Zrotation", "Yrotation", "Xrotation")
    first_channel: np.ndarray    # (N,) column of the joint's first channel in a motion line
    is_end_site: np.ndarray      # (N,) bool

    @property
    def channel_count(self) -> int:
        return int(sum(len(c) for c in self.channels))

    def index(self, name: str) -> int:
        return self.names.index(name)


class _Builder:
    """Collects joints while the HIERARCHY lines are read."""

    def __init__(self, path: str):
        self.path = path
        self.names: list[str] = []
        self.parents: list[int] = []
        self.offsets: list[list[float]] = []
        self.channels: list[tuple[str, ...]] = []
        self.ends: list[bool] = []
        self.stack: list[int] = []
        self.pending: int | None = None  # joint declared, its '{' not yet seen

    def joint(self, where: str, tok: list[str]) -> None:
        key = tok[0].upper()
        site = key == "END" or (key == "JOINT" and len(tok) == 2 and tok[1].upper() == "SITE" and self.stack)
        if key == "ROOT" and self.stack:
            raise TakeError(f"{where}: ROOT inside another joint")
        if not self.stack and self.names:
            raise TakeError(f"{where}: {tok[0]} outside any joint (a second root or an extra '}}')")
        if site and not self.stack:
            raise TakeError(f"{where}: End Site outside any joint")
        if site:
            name = f"{self.names[self.stack[-1]]}_end"
        elif len(tok) < 2:
            raise TakeError(f"{where}: {tok[0]} without a name")
        else:
            name = " ".join(tok[1:])
        if name in self.names:
            raise TakeError(f"{where}: joint name {name!r} used twice")
        self.names.append(name)
        self.parents.append(self.stack[-1] if self.stack else -1)
        self.offsets.append([0.0, 0.0, 0.0])
        self.channels.append(())
        self.ends.append(bool(site))
        self.pending = len(self.names) - 1

    def offset(self, where: str, tok: list[str]) -> None:
        if not self.stack:
            raise TakeError(f"{where}: OFFSET outside a joint")
        try:
            off = [float(v) for v in tok[1:4]]
        except ValueError:
            raise TakeError(f"{where}: OFFSET has a non-numeric value") from None
        if len(off) != 3 or not np.all(np.isfinite(off)):
            raise TakeError(f"{where}: OFFSET needs 3 finite numbers")
        self.offsets[self.stack[-1]] = off

    def channel_list(self, where: str, tok: list[str]) -> None:
        if not self.stack:
            raise TakeError(f"{where}: CHANNELS outside a joint")
        try:
            n = int(tok[1])
        except (IndexError, ValueError):
            raise TakeError(f"{where}: CHANNELS needs a count") from None
        chans = tuple(tok[2:])
        if len(chans) != n:
            raise TakeError(f"{where}: CHANNELS says {n} but lists {len(chans)}")
        unknown = [c for c in chans if c.lower() not in _AXES]
        if unknown:
            raise TakeError(f"{where}: unknown channel {unknown[0]!r}")
        if chans and self.ends[self.stack[-1]]:
            raise TakeError(f"{where}: an End Site cannot have channels")
        self.channels[self.stack[-1]] = tuple(_CANONICAL[c.lower()] for c in chans)


def parse_hierarchy(path: str, lines: list[str]) -> tuple[BvhSkeleton, int]:
    """Parse HIERARCHY ... up to MOTION; returns the skeleton and the index of the MOTION line."""
    b = _Builder(path)
    motion_line = -1
    for i, raw in enumerate(lines):
        tok = raw.split()
        if not tok:
            continue
        key = tok[0].upper()
        where = f"{path}:{i + 1}"
        if not b.names and key == "HIERARCHY":
            continue
        if i == 0 or (not b.names and key not in ("ROOT", "JOINT")):  # (a HIERARCHY line was skipped above)
            raise TakeError(f"{where}: not a BVH file (first line should be HIERARCHY)")
        if key in ("ROOT", "JOINT") or (key == "END" and len(tok) > 1 and tok[1].upper() == "SITE"):
            b.joint(where, tok)
        elif key == "{":
            if b.pending is None:
                raise TakeError(f"{where}: '{{' without a joint")
            b.stack.append(b.pending)
            b.pending = None
        elif key == "}":
            if not b.stack:
                raise TakeError(f"{where}: unbalanced '}}'")
            b.stack.pop()
        elif key == "OFFSET":
            b.offset(where, tok)
        elif key == "CHANNELS":
            b.channel_list(where, tok)
        elif key == "MOTION":
            motion_line = i
            break
        else:
            raise TakeError(f"{where}: unexpected {tok[0]!r} in HIERARCHY")
    if not b.names:
        raise TakeError(f"{path}: BVH file has no ROOT joint")
    if motion_line < 0:
        raise TakeError(f"{path}: BVH file has no MOTION section (truncated?)")
    if b.stack or b.pending is not None:
        raise TakeError(f"{path}:{motion_line + 1}: HIERARCHY not closed before MOTION (missing '}}')")
    counts = np.array([len(c) for c in b.channels])
    first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    return BvhSkeleton(tuple(b.names), np.array(b.parents, dtype=np.int64), np.array(b.offsets, dtype=np.float64),
                       tuple(b.channels), first, np.array(b.ends, dtype=bool)), motion_line


def parse_motion_header(path: str, lines: list[str], motion_line: int) -> tuple[int, float, int]:
    """'Frames: N' and 'Frame Time: t' after MOTION; returns (frames, frame_time, first data line index)."""
    frames = frame_time = None
    i = motion_line + 1
    while i < len(lines) and (frames is None or frame_time is None):
        text = lines[i].strip()
        low = text.lower()
        if low.startswith("frames:"):
            try:
                frames = int(text.split(":", 1)[1])
            except ValueError:
                raise TakeError(f"{path}:{i + 1}: 'Frames:' needs a whole number") from None
        elif low.startswith("frame time:"):
            try:
                frame_time = float(text.split(":", 1)[1])
            except ValueError:
                raise TakeError(f"{path}:{i + 1}: 'Frame Time:' needs a number") from None
        elif text:
            raise TakeError(f"{path}:{i + 1}: expected 'Frames:' and 'Frame Time:' after MOTION")
        i += 1
    if frames is None or frame_time is None:
        raise TakeError(f"{path}: MOTION section lacks 'Frames:' or 'Frame Time:' (truncated?)")
    if frames < 1:
        raise TakeError(f"{path}: BVH file has no frames ('Frames: {frames}'): nothing to bake")
    if not (np.isfinite(frame_time) and frame_time > 0):
        raise TakeError(f"{path}: frame time must be positive, got {frame_time}")
    return frames, frame_time, i


def read_bvh_text(path: str | os.PathLike) -> tuple[BvhSkeleton, float, np.ndarray, np.ndarray]:
    """(skeleton, frame time in seconds, (F, C) channel values as written (NaN kept), (F,) their file lines)."""
    path = os.fspath(path)
    data = read_bytes(path)
    if not looks_like(data[:4096]):
        raise TakeError(f"{path}:1: not a BVH file (first line should be HIERARCHY)")
    lines = data.decode("utf-8-sig", errors="replace").splitlines()
    sk, motion_line = parse_hierarchy(path, lines)
    frames, frame_time, first = parse_motion_header(path, lines, motion_line)
    body = "\n".join(lines[first:]).encode("latin-1", errors="replace")
    if sk.channel_count == 0:
        raise TakeError(f"{path}: BVH hierarchy has no channels: no motion to read")
    values, line_numbers = parse_table(path, body, sk.channel_count, first_line=first + 1, what="motion line")
    if values.shape[0] < frames:
        last = f" (file truncated after line {int(line_numbers[-1])})" if values.shape[0] else ""
        raise TakeError(f"{path}: 'Frames: {frames}' but only {values.shape[0]} motion lines{last}")
    if values.shape[0] > frames:
        raise TakeError(f"{path}:{int(line_numbers[frames])}: more motion lines than 'Frames: {frames}'")
    return sk, frame_time, values, line_numbers
