"""NTU RGB+D `.skeleton` text files (Kinect v2, 25 joints, 30 fps).

Layout: the frame count; per frame a body count; per body a line of 10 values (body id, clipped edges,
hand confidences and states, restricted, lean x/y, tracking state), the joint count, then one line per joint
of 12 values: x y z (camera space, metres), depth x y and colour x y (pixels), orientation w x y z, tracking
state. Body N of a take is the (N+1)th body listed in each frame (NTU lists its performers in a steady order;
`read(path, body=1)` reads the second performer of a two-person action); frames without that body are
NOT_TRACKED (NaN positions). `metadata["bodies"]` is the most bodies any frame lists.
"""
from __future__ import annotations

import os
import warnings

import numpy as np

from ..core.skeletons import KINECT_V2, NOT_TRACKED
from ..core.take import Take, TakeError
from ._kinect_v2_images import COLOR_SIZE, DEPTH_SIZE, unmirror
from ._numeric import _raise_non_numeric, field_counts, normalise, read_bytes
from ._screening import screen_joints
from ._timebase import FRAME_ORDER

RATE = 30.0
BODY_FIELDS = 10
JOINT_FIELDS = 12


def looks_like(head: bytes) -> bool:
    lines = head.split(b"\n")
    if len(lines) < 4:
        return False
    counts = [len(line.split()) for line in lines[:4]]
    if counts[:2] != [1, 1] or not (lines[0].strip().isdigit() and lines[1].strip().isdigit()):
        return False
    if int(lines[1]) == 0:  # first frame has no body: the next line is the next frame's body count
        return counts[2] in (1,) and lines[2].strip().isdigit()
    return counts[2] == BODY_FIELDS and counts[3] == 1 and lines[3].strip() == b"25"


def read(path: str | os.PathLike, body: int = 0) -> Take:
    return read_with_2d(path, body)[0]


def read_with_2d(path: str | os.PathLike, body: int = 0) -> tuple[Take, dict[str, np.ndarray]]:
    """The take plus (F, 25, ...) arrays `depth_px`, `color_px` (pixels in the 512x424 depth and
    1920x1080 colour images of the Kinect SDK, which are mirrored: u grows with camera X),
    `depth_px_unmirrored`, `color_px_unmirrored` (u flipped to the project convention, the image as the
    camera sees it), `orientation` (w, x, y, z), and (F,) `body_count`."""
    path = os.fspath(path)
    text = normalise(read_bytes(path))
    counts = field_counts(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        flat = np.fromstring(text.decode("latin-1"), dtype=np.float64, sep=" ")
    nonblank = np.flatnonzero(counts)
    if flat.size != counts.sum():
        _raise_non_numeric(path, text, nonblank, 1, "line")
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])  # index in `flat` of each line's first value
    lines = nonblank  # walk non-blank lines only; report 1-based file line numbers

    def need(k: int, n: int, what: str) -> int:
        if k >= lines.size:
            raise TakeError(f"{path}: file ends early, expected {what} (truncated?)")
        li = int(lines[k])
        if counts[li] != n:
            raise TakeError(f"{path}:{li + 1}: expected {n} value{'s' if n > 1 else ''} ({what}), "
                            f"found {int(counts[li])}")
        return li

    def whole(li: int, what: str) -> int:
        v = flat[start[li]]
        if not (np.isfinite(v) and v >= 0 and v == int(v)):
            raise TakeError(f"{path}:{li + 1}: {what} must be a whole number, found {v:g}")
        return int(v)

    n_frames = whole(need(0, 1, "frame count"), "frame count")
    if n_frames == 0:
        raise TakeError(f"{path}:1: frame count is 0")
    layout = _layout_fast(counts[lines], flat[start[lines]], n_frames, body)
    if layout is None:  # something is off: walk the file in order to name the first bad line
        layout = _layout_walk(path, lines, counts, n_frames, need, whole, body)
    joint_line, body_count, all_joints = layout
    if body >= max(1, int(body_count.max())):
        raise TakeError(f"{path}: no body {body} (bodies are numbered from 0; frames list at most "
                        f"{int(body_count.max())})")
    # Every joint line at once: check widths, then gather the first bodies' values.
    every = lines[(all_joints[:, None] + np.arange(len(KINECT_V2))).ravel()]
    bad = counts[every] != JOINT_FIELDS
    if bad.any():
        li = int(every[np.argmax(bad)])
        raise TakeError(f"{path}:{li + 1}: expected {JOINT_FIELDS} values (joint line), found {int(counts[li])}")
    has = joint_line >= 0
    jl = lines[(joint_line[has, None] + np.arange(len(KINECT_V2))).ravel()]
    vals = flat[start[jl][:, None] + np.arange(JOINT_FIELDS)].reshape(-1, len(KINECT_V2), JOINT_FIELDS)
    state_vals = vals[..., 11]
    bad = ~np.isin(state_vals, (0, 1, 2))
    if bad.any():
        li = int(jl.reshape(-1, len(KINECT_V2))[np.unravel_index(np.argmax(bad), bad.shape)])
        raise TakeError(f"{path}:{li + 1}: tracking state must be 0, 1 or 2")
    nj = len(KINECT_V2)
    table = np.full((n_frames, nj, JOINT_FIELDS), np.nan)
    table[has] = vals
    states = np.zeros((n_frames, nj), dtype=np.uint8)
    states[has] = state_vals.astype(np.uint8)
    if not np.any(states != NOT_TRACKED):
        raise TakeError(f"{path}: no tracked body{f' {body}' if body else ''} in any of its {n_frames} frames")
    times = np.arange(n_frames) / RATE
    meta = {"source_file": os.path.basename(path), "time_unit": FRAME_ORDER, "max_bodies": int(body_count.max()),
            "bodies": int(body_count.max()), "frames_without_body": int(np.sum(~has)),
            **({"body": body} if body else {})}
    where = np.zeros((n_frames, nj), dtype=np.int64)
    where[has] = jl.reshape(-1, nj) + 1
    before = states
    positions, states = screen_joints(path, table[..., :3], states, where, meta,
                                      values_ok=np.all(np.isfinite(table[..., 3:11]), axis=2))
    table[states != before] = np.nan  # dropped samples: their 2D values are not to be trusted either
    take = Take(KINECT_V2, positions, states, times, RATE, "ntu_skeleton", meta)
    depth, color = table[..., 3:5], table[..., 5:7]
    return take, {"depth_px": depth, "color_px": color, "orientation": table[..., 7:11],
                  "depth_px_unmirrored": unmirror(depth, DEPTH_SIZE[0]),
                  "color_px_unmirrored": unmirror(color, COLOR_SIZE[0]), "body_count": body_count}


def _layout_fast(kinds: np.ndarray, first: np.ndarray, n_frames: int, body: int = 0):
    """The frame/body layout from line widths alone (vectorised), or None if it is not consistent:
    per frame the first joint line of body `body` (-1 where the frame lists fewer), body counts, and the
    first joint line of every body."""
    per_body = 2 + len(KINECT_V2)
    bodies = np.flatnonzero(kinds == BODY_FIELDS)
    if np.any(bodies + 1 >= kinds.size) or np.any(first[bodies + 1] != len(KINECT_V2)):
        return None
    single = kinds == 1
    single[0] = False
    single[bodies + 1] = False
    heads = np.flatnonzero(single)
    if heads.size != n_frames:
        return None
    nb = first[heads]
    if np.any((nb < 0) | (nb != np.round(nb))):
        return None
    nb = nb.astype(np.int64)
    nxt = heads + 1 + per_body * nb
    if np.any(nxt[:-1] != heads[1:]) or nxt[-1] != kinds.size or nb.sum() != bodies.size:
        return None
    rank = np.arange(bodies.size) - np.repeat(np.cumsum(nb) - nb, nb)
    if np.any(np.repeat(heads + 1, nb) + per_body * rank != bodies):
        return None
    joint_line = np.where(nb > body, heads + 3 + per_body * body, -1)
    return joint_line, nb, bodies + 2


def _layout_walk(path, lines, counts, n_frames, need, whole, body: int = 0):
    """Walk frame by frame; raises TakeError at the first line that breaks the layout."""
    k = 1
    joint_line = np.full(n_frames, -1, dtype=np.int64)  # first joint line of body `body`, per frame
    body_count = np.zeros(n_frames, dtype=np.int64)
    all_joints: list[int] = []                           # first joint line of every body
    for f in range(n_frames):  # body counts vary per frame: the layout can only be walked in order
        li = need(k, 1, f"body count of frame {f + 1}")
        nb = body_count[f] = whole(li, "body count")
        k += 1
        for b in range(nb):
            need(k, BODY_FIELDS, f"body {b + 1} of frame {f + 1}")
            nj = whole(need(k + 1, 1, "joint count"), "joint count")
            if nj != len(KINECT_V2):
                raise TakeError(f"{path}:{int(lines[k + 1]) + 1}: expected 25 joints, found {nj}")
            if k + 2 + nj > lines.size:
                raise TakeError(f"{path}:{int(lines[-1]) + 1}: file ends inside frame {f + 1} (truncated?)")
            all_joints.append(k + 2)
            if b == body:
                joint_line[f] = k + 2
            k += 2 + nj
    if k < lines.size:
        raise TakeError(f"{path}:{int(lines[k]) + 1}: data after the last of the {n_frames} frames "
                        f"(frame count wrong?)")
    return joint_line, body_count, np.asarray(all_joints, dtype=np.int64)
