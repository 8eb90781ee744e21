"""The project's own take format, `.krtake` (docs/take_format.md): a JSON header line, then one text line per
frame, `t x0 y0 z0 s0 x1 y1 z1 s1 ...`. Line-based so a live recording can append frame by frame and a
crash loses at most the line being written.
"""
from __future__ import annotations

import json
import os
from typing import IO

import numpy as np

from ..core.skeletons import SKELETONS, Skeleton
from ..core.take import Take, TakeError
from ._numeric import parse_table
from ._screening import screen_joints
from ._timebase import stamps_to_seconds

MAGIC = "kinect_retarget.take"
VERSION = 1


def looks_like(head: bytes) -> bool:
    return head.lstrip().startswith(b"{") and MAGIC.encode() in head[:400]


def header_dict(skeleton: Skeleton, rate: float, metadata: dict | None = None) -> dict:
    # `time_unit` describes the file's own time column: the header says it; a source's unit is not carried;
    # nor is the source's body count (a .krtake holds one body: `body` says which one it was)
    metadata = {k: v for k, v in (metadata or {}).items() if k not in ("time_unit", "bodies")}
    return {"format": MAGIC, "version": VERSION, "skeleton": skeleton.name, "joints": list(skeleton.joints),
            "rate": float(rate), "units": "m", "space": "kinect_camera", "time_unit": "s",
            "metadata": metadata}


def format_rows(times: np.ndarray, positions: np.ndarray, states: np.ndarray) -> str:
    """Frame lines for (F,) times, (F, J, 3) positions, (F, J) states; untracked NaNs are written as 0."""
    f, j = states.shape
    block = np.empty((f, j, 4))
    block[..., :3] = np.nan_to_num(positions, nan=0.0)
    block[..., 3] = states
    cols = np.concatenate([np.asarray(times, dtype=np.float64)[:, None], block.reshape(f, -1)], axis=1)
    fmt = " ".join(["%.6f"] + ["%.5f %.5f %.5f %d"] * j)
    return "".join(fmt % tuple(row) + "\n" for row in cols)


class TakeWriter:
    """Appends frames to a .krtake file as they arrive (live recording); flushes every frame."""

    def __init__(self, path: str | os.PathLike, skeleton: Skeleton, rate: float, metadata: dict | None = None):
        self.path = os.fspath(path)
        self.skeleton = skeleton
        self.frames = 0
        self._fh: IO[str] | None = open(self.path, "w", encoding="utf-8", newline="\n")
        self._fh.write(json.dumps(header_dict(skeleton, rate, metadata)) + "\n")
        self._fh.flush()

    def write(self, time: float, positions: np.ndarray, states: np.ndarray) -> None:
        if self._fh is None:
            raise ValueError(f"take writer for {self.path} is closed")
        self._fh.write(format_rows(np.array([time]), positions[None], states[None]))
        self._fh.flush()
        self.frames += 1

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def __enter__(self) -> TakeWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def write(path: str | os.PathLike, take: Take) -> None:
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(json.dumps(header_dict(take.skeleton, take.rate, take.metadata)) + "\n")
        fh.write(format_rows(take.times, take.positions, take.states))


def read(path: str | os.PathLike) -> Take:
    path = os.fspath(path)
    try:
        with open(path, encoding="utf-8") as fh:
            first = fh.readline()
            body = fh.read()
    except UnicodeDecodeError as exc:
        raise TakeError(f"{path}: not a text take (byte {exc.start} is not UTF-8)") from None
    try:
        header = json.loads(first)
    except json.JSONDecodeError as exc:
        raise TakeError(f"{path}:1: take header is not valid JSON ({exc.msg})") from None
    if not isinstance(header, dict):
        raise TakeError(f"{path}:1: take header must be a JSON object")
    if header.get("format") != MAGIC:
        raise TakeError(f"{path}:1: not a kinect_retarget take (format field is {header.get('format')!r})")
    if header.get("version") != VERSION:
        raise TakeError(f"{path}:1: take version {header.get('version')!r} is not supported (this reader "
                        f"reads version {VERSION})")
    skeleton = SKELETONS.get(header.get("skeleton", ""))
    if skeleton is None:
        raise TakeError(f"{path}:1: unknown skeleton {header.get('skeleton')!r} (known: {', '.join(SKELETONS)})")
    if list(header.get("joints", skeleton.joints)) != list(skeleton.joints):
        raise TakeError(f"{path}:1: joint list does not match skeleton {skeleton.name}")
    ncol = 1 + 4 * len(skeleton)
    lines = body.splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    warnings_ = []
    if lines and not body.endswith("\n") and len(lines[-1].split()) < ncol:
        # a recording interrupted mid-write: keep every complete frame, say what was dropped
        lines.pop()
        warnings_.append(f"{path}:{len(lines) + 2}: last frame line was cut off (interrupted recording); "
                         f"{len(lines)} complete frames loaded")
    if not lines:
        raise TakeError(f"{path}: take has no frames")
    values, line_numbers = parse_table(path, "\n".join(lines).encode("utf-8"), ncol, first_line=2,
                                       what="frame line")
    block = values[:, 1:].reshape(-1, len(skeleton), 4)
    states = block[..., 3]
    bad = ~np.isin(states, (0, 1, 2))
    if bad.any():
        raise TakeError(f"{path}:{int(line_numbers[np.argmax(bad.any(axis=1))])}: tracking states must be "
                        f"0, 1 or 2")
    try:
        rate = float(header.get("rate", 30.0))
    except (TypeError, ValueError):
        raise TakeError(f"{path}:1: rate must be a number, got {header.get('rate')!r}") from None
    metadata = header.get("metadata", {})
    if not isinstance(metadata, dict):
        raise TakeError(f"{path}:1: metadata must be a JSON object")
    metadata = {**metadata, "warnings": list(metadata.get("warnings", [])) + warnings_}
    # the header declares the unit of the time column (version 1 writes seconds)
    times, unit = stamps_to_seconds(path, values[:, 0], line_numbers, unit=header.get("time_unit", "s"),
                                    keep_origin=True)
    metadata["time_unit"] = unit
    positions, states = screen_joints(path, block[..., :3], states.astype(np.uint8), line_numbers, metadata)
    if not metadata["warnings"]:
        del metadata["warnings"]
    return _make(path, skeleton, positions, states, times, rate, metadata)


def _make(path, skeleton, positions, states, times, rate, metadata) -> Take:
    try:
        return Take(skeleton, positions, states, times, rate, "krtake", dict(metadata))
    except TakeError as exc:
        raise TakeError(f"{path}: {exc}") from None
