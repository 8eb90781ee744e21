"""Kinectron recordings (JSON): an array of body frames, each with 25 Kinect v2 joints in 3D and 2D.

Frame: `{bodyIndex, tracked, trackingId, leftHandState, rightHandState, joints[25], record_startime,
record_timestamp}`; joint: `{depthX, depthY, colorX, colorY, cameraX, cameraY, cameraZ, orientationX..W}`.
Kinectron reports no per-joint state: every joint of a tracked body is TRACKED, a body with `tracked: false`
is NOT_TRACKED. `read_with_2d` also returns the depth/colour image coordinates for 2D-to-3D lifting.

Bodies: the tracking ids of tracked records, in the order they first appear. When two ids are ever tracked at
the same timestamp the file holds several performers and body N is the records of the Nth id only (untracked
where that id is absent); otherwise it holds one performer, whose id may change when the sensor reacquires
them, and body 0 takes whichever body is tracked. `metadata["bodies"]` says which case it is.
"""
from __future__ import annotations

import json
import os

import numpy as np

from ..core.skeletons import KINECT_V2, TRACKED
from ..core.take import Take, TakeError, nominal_rate
from ._kinect_v2_images import COLOR_SIZE, DEPTH_SIZE, unmirror
from ._numeric import read_bytes
from ._screening import screen_joints
from ._timebase import stamps_to_seconds

_FIELDS = ("cameraX", "cameraY", "cameraZ", "depthX", "depthY", "colorX", "colorY",
           "orientationW", "orientationX", "orientationY", "orientationZ")


def looks_like(head: bytes) -> bool:
    text = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    return text.startswith(b"[") and b'"joints"' in text and b'"cameraX"' in text


def read(path: str | os.PathLike, body: int = 0) -> Take:
    return read_with_2d(path, body)[0]


def read_with_2d(path: str | os.PathLike, body: int = 0) -> tuple[Take, dict[str, np.ndarray]]:
    """The take plus per-frame, per-joint 2D data (all (F, 25, ...) arrays, NaN where not tracked):

    * `depth`, `color`: normalised [0, 1] image coordinates (x right, y down), as Kinectron stores them;
    * `depth_px`, `color_px`: the same in pixels of the 512x424 depth and 1920x1080 colour images. These are
      the Kinect SDK's images, which are MIRRORED: u grows with camera X (u ~ cx + f X / z);
    * `depth_px_unmirrored`, `color_px_unmirrored`: u flipped (W - 1 - u) to the project convention, the
      image as the camera sees it (u ~ cx - f X / z, see core/conventions.py);
    * `orientation`: Kinect joint orientations as quaternions (w, x, y, z), zero for leaf joints;
    * `left_hand_state`, `right_hand_state`: (F,) Kinect hand states (0 unknown ... 4 lasso).
    """
    path = os.fspath(path)
    frames = _load(path)
    ids = performer_ids(frames)
    if body >= len(ids):
        raise TakeError(f"{path}: no body {body} (bodies are numbered from 0; the recording holds {len(ids)})")
    frames = _one_body_per_time(path, frames, ids[body] if len(ids) > 1 else None)
    n, nj = len(frames), len(KINECT_V2)
    table = np.full((n, nj, len(_FIELDS)), np.nan)
    states = np.zeros((n, nj), dtype=np.uint8)
    times = np.empty(n)
    hands = np.zeros((n, 2))
    for i, (rec, fr) in enumerate(frames):  # JSON objects: one Python pass is unavoidable
        times[i] = _number(path, rec, fr, "record_timestamp")
        hands[i] = fr.get("leftHandState", 0) or 0, fr.get("rightHandState", 0) or 0
        if not fr.get("tracked", False):
            continue
        joints = fr.get("joints")
        if not isinstance(joints, list) or len(joints) != nj:
            got = len(joints) if isinstance(joints, list) else "no"
            raise TakeError(f"{path}: record {rec}: expected {nj} joints, found {got}")
        try:
            table[i] = [[j[k] for k in _FIELDS] for j in joints]
        except (KeyError, TypeError) as exc:
            raise TakeError(f"{path}: record {rec}: joint without {exc} value") from None
        except ValueError:
            raise TakeError(f"{path}: record {rec}: non-numeric joint value") from None
        states[i] = TRACKED
    tracked = states[:, 0] == TRACKED
    if not tracked.any():
        raise TakeError(f"{path}: no tracked body in any of its {n} records")
    records = np.array([rec for rec, _ in frames])
    times_s, unit = stamps_to_seconds(path, times, records, label="record", what="record_timestamp",
                                      default="ms")
    first = frames[int(np.argmax(tracked))][1]
    meta = {"source_file": os.path.basename(path), "time_unit": unit,
            "record_startime_ms": first.get("record_startime"), "tracking_id": str(first.get("trackingId", "")),
            "first_timestamp": float(times[0]), "bodies": len(ids), **({"body": body} if body else {})}
    # a joint with a NaN or missing image coordinate is as unusable as one with a bad camera position
    before = states
    positions, states = screen_joints(path, table[..., :3], states, records, meta, label="record",
                                      values_ok=np.all(np.isfinite(table[..., 3:7]), axis=2))
    table[states != before] = np.nan  # dropped samples: their 2D values are not to be trusted either
    take = Take(KINECT_V2, positions, states, times_s, nominal_rate(times_s), "kinectron_json", meta,
                hands.astype(np.uint8))
    depth_px, color_px = table[..., 3:5] * DEPTH_SIZE, table[..., 5:7] * COLOR_SIZE
    two_d = {
        "depth": table[..., 3:5], "color": table[..., 5:7], "depth_px": depth_px, "color_px": color_px,
        "depth_px_unmirrored": unmirror(depth_px, DEPTH_SIZE[0]),
        "color_px_unmirrored": unmirror(color_px, COLOR_SIZE[0]),
        "orientation": table[..., 7:11],
        "left_hand_state": hands[:, 0].astype(np.uint8), "right_hand_state": hands[:, 1].astype(np.uint8),
    }
    return take, two_d


def _load(path: str) -> list:
    data = read_bytes(path)
    try:
        doc = json.loads(data.decode("utf-8-sig"))
    except UnicodeDecodeError:
        raise TakeError(f"{path}: not UTF-8 text") from None
    except json.JSONDecodeError as exc:
        raise TakeError(f"{path}:{exc.lineno}: invalid JSON at column {exc.colno} ({exc.msg}; "
                        f"truncated file?)") from None
    if not isinstance(doc, list):
        raise TakeError(f"{path}: expected a JSON array of body frames")
    if not doc:
        raise TakeError(f"{path}: recording has no frames")
    for rec, fr in enumerate(doc):
        if not isinstance(fr, dict):
            raise TakeError(f"{path}: record {rec}: expected a body object")
    return doc


def performer_ids(frames: list) -> list:
    """The performers' tracking ids in order of appearance when several are tracked at one timestamp, else
    [None] (one performer, whatever ids the sensor gave them)."""
    order: dict = {}
    together: set = set()
    at: dict = {}
    for fr in frames:
        if not fr.get("tracked"):
            continue
        tid = fr.get("trackingId")
        order.setdefault(tid, len(order))
        seen = at.setdefault(fr.get("record_timestamp"), set())
        seen.add(tid)
        if len(seen) > 1:
            together.update(seen)
    return [tid for tid in order if tid in together] if together else [None]


def _one_body_per_time(path: str, frames: list, want=None) -> list[tuple[int, dict]]:
    """Kinectron writes one object per body: keep one per timestamp. `want` None: the first tracked body
    (the one with the first tracking id seen, when several are tracked at once); else only body `want`,
    an untracked record at timestamps without it."""
    first_id = want if want is not None else next((f.get("trackingId") for f in frames if f.get("tracked")), None)
    out: list[tuple[int, dict]] = []
    for rec, fr in enumerate(frames):
        if want is not None and fr.get("trackingId") != want:
            fr = {**fr, "tracked": False}  # keeps the timestamp; another performer's joints are not ours
        t = fr.get("record_timestamp")
        if out and t is not None and out[-1][1].get("record_timestamp") == t:
            prev = out[-1][1]
            better = fr.get("tracked") and (not prev.get("tracked") or
                                            (fr.get("trackingId") == first_id != prev.get("trackingId")))
            if better:
                out[-1] = (rec, fr)
            continue
        out.append((rec, fr))
    return out


def _number(path: str, rec: int, fr: dict, key: str) -> float:
    v = fr.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
        raise TakeError(f"{path}: record {rec}: {key} missing or not a number")
    return float(v)
